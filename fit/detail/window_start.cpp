#include <jelly/fit/detail/window_start.hpp>

#include <utility>
#include <vector>

#include <jelly/fit/detail/implicit_euler_ceres.hpp>

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

std::vector<Real> window_start_state(const Trajectory& trajectory, int first) {
  if (first <= 0 || trajectory.integrator != "implicit_euler" ||
      trajectory.integrator_states.empty())
    return {};
  return trajectory.integrator_states[first];  // as the recording's run carried it
}

Simulator window_simulator(const Trajectory& trajectory, const Model& model, int first,
                           const State& start, int threads) {
  Simulator sim = fresh_window_simulator(trajectory, model, start, threads);
  const std::vector<Real> carried = window_start_state(trajectory, first);
  if (!carried.empty()) sim.integrator().restore_internal_state(carried);
  return sim;
}

}  // namespace jelly
