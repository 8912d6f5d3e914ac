#include <jelly/fit/detail/window_start.hpp>

#include <cmath>
#include <utility>
#include <vector>

#include <jelly/fit/implicit_euler_ceres.hpp>

namespace jelly {

namespace {

Simulator fresh_window_simulator(const Trajectory& trajectory, const Model& model,
                                 const State& start, int threads) {
  SimulatorOptions options;
  options.dt = trajectory.dt;
  options.threads = threads;
  Simulator sim(model, start,
                make_fit_integrator(trajectory.integrator, trajectory.integrator_options), options);
  sim.set_body_contact(trajectory.body_contact);
  for (auto& terrain : trajectory.make_terrains()) sim.add_terrain(std::move(terrain));
  return sim;
}

}  // namespace

std::vector<Real> window_start_state(const Trajectory& trajectory, const Model& model, int first,
                                     int threads) {
  if (first <= 0 || trajectory.integrator != "implicit_euler") return {};
  if (!trajectory.integrator_states.empty())  // as the recording's run carried it
    return trajectory.integrator_states[first];
  Simulator before =
      fresh_window_simulator(trajectory, model, trajectory.state(first - 1), threads);
  const long steps =
      std::lround((trajectory.times[first] - trajectory.times[first - 1]) / trajectory.dt);
  for (long i = 0; i < steps; ++i)
    if (!before.step().ok) return {};
  if (!before.state().x.allFinite()) return {};
  return before.integrator().internal_state();
}

Simulator window_simulator(const Trajectory& trajectory, const Model& model, int first,
                           const State& start, int threads, const std::vector<Real>* carried) {
  Simulator sim = fresh_window_simulator(trajectory, model, start, threads);
  if (carried != nullptr) {
    sim.integrator().restore_internal_state(*carried);
  } else if (first > 0 && trajectory.integrator == "implicit_euler") {
    sim.integrator().restore_internal_state(window_start_state(trajectory, model, first, threads));
  }
  return sim;
}

}  // namespace jelly
