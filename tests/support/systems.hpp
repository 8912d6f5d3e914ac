#pragma once
// Small systems with analytic answers, shared by the tests.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <jelly/core/measures.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/body_contact_params.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly::testing {

// Two particles of mass m on the x axis joined by one spring (ks, kd, rest length l0), no
// gravity; the spring starts stretched by `stretch`, at rest.
struct TwoParticleSpring {
  Real m = 1, ks = 100, kd = 0, l0 = 1, stretch = 0.1;

  Model model() const {
    Model model;
    model.mass = VecX::Constant(2, m);
    model.rest_position = VecX::Zero(6);
    model.rest_position[3] = l0;
    model.springs.add(0, 1, l0, {ks, kd}, SpringType::kStructural);
    model.gravity.setZero();
    return model;
  }
  State initial() const {
    State s;
    s.x = VecX::Zero(6);
    s.x[0] = -stretch / 2;
    s.x[3] = l0 + stretch / 2;
    s.v = VecX::Zero(6);
    return s;
  }
  // Relative coordinate r = x1 - x0 with reduced mass mu = m / 2:
  // mu r'' = -ks (r - l0) - kd r', r(0) = l0 + stretch, r'(0) = 0.
  Real gamma() const { return kd / m; }  // kd / (2 mu)
  Real omega0() const { return std::sqrt(2 * ks / m); }
  Real omega_d() const { return std::sqrt(omega0() * omega0() - gamma() * gamma()); }
  Real length(Real t) const {
    const Real g = gamma(), w = omega_d();
    return l0 + stretch * std::exp(-g * t) * (std::cos(w * t) + g / w * std::sin(w * t));
  }
  Real length_rate(Real t) const {
    const Real g = gamma(), w = omega_d();
    return -stretch * std::exp(-g * t) * (g * g / w + w) * std::sin(w * t);
  }
};

// One free particle of 1 kg at the origin, under gravity.
inline Model single_particle() {
  Model m;
  m.mass = VecX::Constant(1, 1.0);
  m.rest_position = VecX::Zero(3);
  return m;
}

// The smallest signed distance of the simulator's particles from `terrain` (< 0: inside).
inline Real min_distance(const Simulator& sim, const Terrain& terrain) {
  Real d = std::numeric_limits<Real>::infinity();
  for (int i = 0; i < sim.model().num_particles(); ++i)
    d = std::min(d, terrain.signed_distance(particle(sim.state().x, i), sim.state().t));
  return d;
}

// The largest particle speed of a state.
inline Real max_speed(const State& s) {
  Real v = 0;
  for (int i = 0; i < s.v.size() / 3; ++i) v = std::max(v, particle(s.v, i).norm());
  return v;
}

// A small jelly cube (n per edge) of the seed's material, corner at `origin`.
inline CubeSpec small_cube(int n = 4, Real edge = 1, Vec3 origin = Vec3(0, 0.5, 0)) {
  CubeSpec spec;
  spec.n = n;
  spec.edge_length = edge;
  spec.origin = origin;
  return spec;
}

// Rotates a state's positions about the z axis by `degrees` around `pivot`.
inline void rotate_about_z(State& s, Real degrees, const Vec3& pivot) {
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(degrees * M_PI / 180.0, Vec3::UnitZ()).toRotationMatrix();
  for (int i = 0; i < s.x.size() / 3; ++i)
    particle(s.x, i) = pivot + r * (particle(s.x, i) - pivot);
}

// A cube state turned to lie flat on a slope of `degrees` through the origin, 1 mm above it.
inline State cube_on_slope(const Model& m, Real degrees) {
  State s = rest_state(m);
  // Corner at the origin, rotated so that its bottom face lies in the slope.
  const Vec3 corner = particle(s.x, 0);
  for (int i = 0; i < m.num_particles(); ++i) particle(s.x, i) -= corner - Vec3(0, 1e-3, 0);
  rotate_about_z(s, -degrees, Vec3::Zero());
  return s;
}

inline Simulator make_sim(const Model& model, const State& state, const std::string& integrator,
                          Real dt, Real output_interval = 0) {
  SimulatorOptions options;
  options.dt = dt;
  options.output_interval = output_interval;
  return Simulator(model, state, make_integrator(integrator), options);
}

// An observer that records a function of the simulator at every frame.
template <typename F>
class Probe final : public Observer {
 public:
  explicit Probe(F f) : f_(std::move(f)) {}
  void on_frame(const Simulator& sim) override { f_(sim); }

 private:
  F f_;
};
template <typename F>
Probe(F) -> Probe<F>;

// What a resting test looks at: the deepest any particle went into a terrain over the run, and
// the lowest and highest height of the centre of mass once the body has settled.
struct RestWatch {
  RunReport report;
  Real deepest = 0, lowest_late = 1e9, highest_late = -1e9;
};

// Runs `sim` until `until`, watching `terrain` and the centre of mass after `settled` s.
inline RestWatch run_watching_rest(Simulator& sim, const Terrain& terrain, Real settled,
                                   Real until) {
  RestWatch w;
  Probe probe([&](const Simulator& s) {
    w.deepest = std::min(w.deepest, min_distance(s, terrain));
    if (s.state().t > settled) {
      const Real y = center_of_mass(s.model(), s.state()).y();
      w.lowest_late = std::min(w.lowest_late, y);
      w.highest_late = std::max(w.highest_late, y);
    }
  });
  sim.add_observer(probe);
  w.report = sim.run_until(until);
  sim.remove_observer(probe);
  return w;
}

// The time step for the small cubes of the contact tests. Explicit Euler updates positions with
// the velocity from before the contact impulses, and at dt >= 5e-4 the bottom layer of these
// cubes settles into a buzz of about 0.1 m/s (a known limitation, docs/contact.md); a quarter
// step is quiet.
inline Real contact_dt(const std::string& integrator) {
  return integrator == "explicit_euler" ? 2.5e-4 : 1e-3;
}

// A run's total energy (kinetic + elastic + gravitational) from step to step: its largest rise
// in one step, its scale (|E| + the kinetic energy at the start), and the deepest point below
// a terrain (where the terrain can touch it) at any step.
struct EnergyTrace {
  Real worst_growth = 0, scale = 0, deepest = 0;
};

// Steps `sim` to t_end, tracing its energy (every step must succeed).
inline EnergyTrace run_traced(Simulator& sim, Real t_end) {
  EnergyTrace trace;
  Real previous = total_energy(sim.model(), sim.state());
  trace.scale = std::abs(previous) + kinetic_energy(sim.model(), sim.state());
  while (sim.state().t < t_end - 0.5 * sim.options().dt) {
    const StepResult r = sim.step();
    EXPECT_TRUE(r.ok) << r.message;
    if (!r.ok) break;
    const Real e = total_energy(sim.model(), sim.state());
    trace.worst_growth = std::max(trace.worst_growth, e - previous);
    previous = e;
    for (const auto& terrain : sim.terrains()) {
      for (int i = 0; i < sim.model().num_particles(); ++i) {
        const Vec3 p = particle(sim.state().x, i);
        if (terrain->can_contact(p, sim.state().t))
          trace.deepest = std::min(trace.deepest, terrain->signed_distance(p, sim.state().t));
      }
    }
  }
  return trace;
}

// Two n = 4 cubes, mirror images of each other across x = 0 (0.1 m apart), thrown head on at
// 2 m/s each without gravity, frictionless, with the given restitution; the Simulator resolves
// their contact after each step (implicit_euler with contact "after_step"). `kd`: the springs'
// damping.
inline Simulator head_on_cubes(const std::string& integrator, Real dt, Real restitution = 0,
                               int threads = 1, Real kd = 50) {
  Model model;
  CubeSpec a = small_cube(4, 0.3, Vec3(-0.35, 0, 0));
  CubeSpec b = small_cube(4, 0.3, Vec3(0.05, 0, 0));
  for (SpringCoefficients& c : a.springs) c.kd = kd;
  for (SpringCoefficients& c : b.springs) c.kd = kd;
  model.add_body("left", a.shape().build(a.material(), "a."));
  model.add_body("right", b.shape().build(b.material(), "b."));
  model.gravity.setZero();
  State s = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i)
    particle(s.v, i) = Vec3(i < 64 ? 2.0 : -2.0, 0, 0);
  SimulatorOptions so;
  so.dt = dt;
  so.threads = threads;
  IntegratorOptions options;
  options.implicit.contact = ImplicitContactMode::kAfterStep;
  Simulator sim(model, s, make_integrator(integrator, options), so);
  BodyContactParams params;
  params.friction = params.static_friction = 0;
  params.restitution = restitution;
  sim.set_body_contact(params);
  return sim;
}

// How far a state of head_on_cubes is from its mirror image: the largest difference between
// particle (i, j, k) of the left cube and (3 - i, j, k) of the right one mirrored, positions and
// velocities.
inline Real head_on_asymmetry(const State& s) {
  Real asymmetry = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        const int l = (i * 4 + j) * 4 + k, r = 64 + ((3 - i) * 4 + j) * 4 + k;
        const Vec3 xl = particle(s.x, l), xr = particle(s.x, r);
        const Vec3 vl = particle(s.v, l), vr = particle(s.v, r);
        asymmetry = std::max({asymmetry, std::abs(xl.x() + xr.x()), std::abs(xl.y() - xr.y()),
                              std::abs(xl.z() - xr.z()), std::abs(vl.x() + vr.x()),
                              std::abs(vl.y() - vr.y()), std::abs(vl.z() - vr.z())});
      }
  return asymmetry;
}

}  // namespace jelly::testing
