#include <jelly/fit/spring_fit.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <jelly/core/errors.hpp>
#include <jelly/fit/detail/implicit_euler_ceres.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

namespace {

std::string at(const char* field, int k) {
  return std::string("recording.") + field + "[" + std::to_string(k) + "]";
}

}  // namespace

void Trajectory::validate() const {
  model.validate();
  const int t_count = frames();
  require(t_count >= 3, "recording.frames", t_count,
          "at least 3 frames (a start state and two frames to compare)");
  require(std::isfinite(dt) && dt > 0, "recording.dt", dt, "a finite time step > 0 s");
  require(static_cast<int>(positions.size()) == t_count, "recording.positions.size",
          positions.size(), "one frame per time (" + std::to_string(t_count) + ")");
  require(velocities.empty() || static_cast<int>(velocities.size()) == t_count,
          "recording.velocities.size", velocities.size(),
          "0 (none recorded) or one frame per time (" + std::to_string(t_count) + ")");
  require(integrator_states.empty() || static_cast<int>(integrator_states.size()) == t_count,
          "recording.integrator_states.size", integrator_states.size(),
          "0 (none recorded) or one per frame (" + std::to_string(t_count) + ")");
  const Eigen::Index n = model.num_dofs();
  for (int k = 0; k < t_count; ++k) {
    require(std::isfinite(times[k]), at("times", k), times[k], "a finite time");
    require(positions[k].size() == n, at("positions", k) + ".size", positions[k].size(),
            "3 x the number of particles (" + std::to_string(n) + ")");
    require(positions[k].allFinite(), at("positions", k), "a non-finite value", "finite positions");
    if (!velocities.empty()) {
      require(velocities[k].size() == n, at("velocities", k) + ".size", velocities[k].size(),
              "3 x the number of particles (" + std::to_string(n) + ")");
      require(velocities[k].allFinite(), at("velocities", k), "a non-finite value",
              "finite velocities");
    }
    if (k == 0) continue;
    const Real interval = times[k] - times[k - 1];
    require(interval > 0, at("times", k) + " - times[" + std::to_string(k - 1) + "]", interval,
            "> 0 (times strictly increasing)");
    const Real steps = interval / dt;
    require(std::abs(steps - std::round(steps)) <= 1e-6 * std::max<Real>(1, steps),
            at("times", k) + " - times[" + std::to_string(k - 1) + "]", interval,
            "a whole number of steps of dt = " + to_text(dt) +
                " s (the replay steps like the "
                "recording)");
  }
  // Something must move, and some spring must change length, or no coefficient is identifiable.
  Real moved = 0, stretched = 0;
  const Springs& s = model.springs;
  for (int k = 1; k < t_count; ++k) {
    moved = std::max(moved, (positions[k] - positions[0]).lpNorm<Eigen::Infinity>());
    for (int j = 0; j < s.size(); ++j) {
      const Real l0 = (particle(positions[0], s.a[j]) - particle(positions[0], s.b[j])).norm();
      const Real l = (particle(positions[k], s.a[j]) - particle(positions[k], s.b[j])).norm();
      stretched = std::max(stretched, std::abs(l - l0) / s.rest_length[j]);
    }
  }
  require(moved > 0, "recording.positions", "no motion (every frame equals frame 0)",
          "a recording in which the jelly moves");
  require(s.size() > 0, "recording.model.springs.size", 0, "at least one spring to fit");
  require(stretched > 1e-9, "recording.positions",
          "rigid motion (no spring changes length by more than 1e-9 of its rest length)",
          "a recording in which the springs deform");
}

State Trajectory::state(int k) const {
  State s;
  s.t = times[k];
  s.x = positions[k];
  if (!velocities.empty()) {
    s.v = velocities[k];
    return s;
  }
  // Second-order finite differences on a possibly non-uniform grid: the derivative of the
  // parabola through three neighbouring frames, evaluated at frame k.
  const int last = frames() - 1;
  const int c = std::clamp(k, 1, last - 1);  // centre of the three frames used
  const Real t0 = times[c - 1], t1 = times[c], t2 = times[c + 1], t = times[k];
  const Real w0 = ((t - t1) + (t - t2)) / ((t0 - t1) * (t0 - t2));
  const Real w1 = ((t - t0) + (t - t2)) / ((t1 - t0) * (t1 - t2));
  const Real w2 = ((t - t0) + (t - t1)) / ((t2 - t0) * (t2 - t1));
  s.v = w0 * positions[c - 1] + w1 * positions[c] + w2 * positions[c + 1];
  return s;
}

Terrains Trajectory::make_terrains() const { return terrains ? terrains() : Terrains{}; }

Trajectory simulate_trajectory(const Model& model, const State& initial, TerrainFactory terrains,
                               const std::string& integrator, Real dt, Real frame_interval,
                               Real duration, bool record_velocities,
                               const IntegratorOptions& integrator_options,
                               const BodyContactParams& body_contact) {
  require(std::isfinite(frame_interval) && frame_interval >= dt, "frame_interval", frame_interval,
          "a finite interval >= dt");
  require(std::isfinite(duration) && duration > 0, "duration", duration, "a finite time > 0 s");
  Trajectory trajectory;
  trajectory.model = model;
  trajectory.terrains = std::move(terrains);
  trajectory.integrator = integrator;
  trajectory.integrator_options = integrator_options;
  trajectory.dt = dt;
  trajectory.body_contact = body_contact;
  const long steps_per_frame = std::lround(frame_interval / dt);
  require(std::abs(frame_interval / dt - static_cast<Real>(steps_per_frame)) < 1e-6,
          "frame_interval", frame_interval, "a whole number of steps of dt");
  SimulatorOptions options;
  options.dt = dt;
  Simulator sim(model, initial, make_fit_integrator(integrator, integrator_options), options);
  sim.set_body_contact(body_contact);
  for (auto& terrain : trajectory.make_terrains()) sim.add_terrain(std::move(terrain));
  auto record = [&] {
    trajectory.times.push_back(sim.state().t);
    trajectory.positions.push_back(sim.state().x);
    if (record_velocities) trajectory.velocities.push_back(sim.state().v);
    trajectory.integrator_states.push_back(sim.integrator().internal_state());
  };
  record();
  const long frames = std::lround(duration / frame_interval);
  for (long f = 0; f < frames; ++f) {
    for (long i = 0; i < steps_per_frame; ++i) {
      const StepResult result = sim.step();
      if (!result.ok) throw std::runtime_error("simulate_trajectory: " + result.message);
    }
    record();
  }
  return trajectory;
}

}  // namespace jelly
