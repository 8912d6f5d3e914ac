#pragma once
// Shared checks of the discrete adjoints (implicit_euler, projective_dynamics) against central
// finite differences of the simulator's own runs: the loss, the central difference along a change
// of the simulator or the problem, a check of every parameter kind of a body, of the external
// forces' parameters, and a pinned cloth driven by a control sequence.
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/solvers/adjoint/detail/projective_dynamics_adjoint.hpp>
#include <jelly/solvers/simulator.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

// A scene to differentiate: how to build its simulator, and the problem (steps, driven pins).
struct AdjointCase {
  std::function<Simulator()> make;
  int steps = 12;
  std::vector<int> driven;
  std::vector<Vec3> targets;
};

// L = sum over frames K/2 and K of a.x + 0.05 |v|^2 (a fixed random per particle).
struct TestLoss {
  VecX a;
  Real operator()(int /*frame*/, const State& s, VecX& dx, VecX& dv) const {
    dx += a;
    dv += 0.1 * s.v;
    return a.dot(s.x) + 0.05 * s.v.squaredNorm();
  }
};

VecX random_vector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  VecX r(n);
  for (int i = 0; i < n; ++i) r[i] = u(rng);
  return r;
}

GradientProblem problem_of(const AdjointCase& c, const Simulator& sim) {
  GradientProblem p;
  p.steps = c.steps;
  p.loss_frames = {c.steps / 2, c.steps};
  p.loss = TestLoss{random_vector(sim.model().num_dofs(), 7)};
  p.driven_pins = c.driven;
  p.pin_targets = c.targets;
  return p;
}

// The loss of a run after `edit` (the simulator's own steps, the pins driven as the adjoint
// drives them).
Real run_loss(const AdjointCase& c, const std::function<void(Simulator&, GradientProblem&)>& edit) {
  Simulator sim = c.make();
  GradientProblem p = problem_of(c, sim);
  edit(sim, p);
  const Real h = sim.options().dt;
  const int pins = static_cast<int>(p.driven_pins.size());
  Real loss = 0;
  VecX dx(sim.model().num_dofs()), dv(sim.model().num_dofs());
  for (int k = 0; k < p.steps; ++k) {
    for (int q = 0; q < pins; ++q) {
      const int i = p.driven_pins[q];
      const Vec3 now = particle(sim.state().x, i);
      sim.set_pin_target(i, now, (p.pin_targets[k * pins + q] - now) / h);
    }
    const StepResult r = sim.step();
    EXPECT_TRUE(r.ok) << r.message;
    if (k + 1 == p.steps / 2 || k + 1 == p.steps) loss += p.loss(k + 1, sim.state(), dx, dv);
  }
  return loss;
}

// Central difference of the loss along a change `edit(sim, problem, eps)`.
Real central_difference(const AdjointCase& c, Real eps,
                        const std::function<void(Simulator&, GradientProblem&, Real)>& edit) {
  const Real plus = run_loss(c, [&](Simulator& s, GradientProblem& p) { edit(s, p, eps); });
  const Real minus = run_loss(c, [&](Simulator& s, GradientProblem& p) { edit(s, p, -eps); });
  return (plus - minus) / (2 * eps);
}

GradientResult gradient_of(const AdjointCase& c) {
  Simulator sim = c.make();
  const GradientProblem p = problem_of(c, sim);
  return integrator_gradient(sim, p);
}

void expect_close(Real adjoint, Real fd, Real tolerance, const std::string& what) {
  EXPECT_LE(std::abs(adjoint - fd), tolerance * std::abs(fd))
      << what << ": adjoint " << adjoint << " finite differences " << fd;
  EXPECT_NE(fd, 0) << what;
}

constexpr Real kTolerance = 1e-5;

// A state moved off rest (positions by up to `dx`, velocities by up to `dv`): at rest every
// spring sits on the definiteness fix's clamp (s = 0), where the step is not differentiable.
State jittered(State s, Real dx, Real dv) {
  s.x += dx * random_vector(static_cast<int>(s.x.size()), 21);
  s.v += dv * random_vector(static_cast<int>(s.v.size()), 22);
  return s;
}

// One derivative: the adjoint's value against the central difference of the loss along a change
// of the simulator `edit(sim, e)` of step `eps` (or, for the problem's own data, `edit(sim,
// problem, e)`).
using ProblemEdit = std::function<void(Simulator&, GradientProblem&, Real)>;
void check_derivative(const AdjointCase& c, Real adjoint, Real eps, const ProblemEdit& edit,
                      const std::string& what) {
  expect_close(adjoint, central_difference(c, eps, edit), kTolerance, what);
}
void check_derivative(const AdjointCase& c, Real adjoint, Real eps,
                      const std::function<void(Simulator&, Real)>& edit, const std::string& what) {
  check_derivative(
      c, adjoint, eps, [&](Simulator& s, GradientProblem&, Real e) { edit(s, e); }, what);
}

// Checks every parameter kind of body `body` (and the state, gravity, the pins' targets). The
// steps: 1e-6 relative (1e-4 for kd, whose gradients are small enough for round-off to show at
// 1e-6), 1e-8 m for the positions (a spring near its rest length, where the definiteness clamp
// has its kink, must not be crossed).
void check_every_kind(const AdjointCase& c, int body, const std::vector<SpringType>& types) {
  const GradientResult g = gradient_of(c);
  Simulator probe = c.make();
  const Model& m = probe.model();
  for (SpringType t : types) {
    const int at = kSpringTypeCount * body + static_cast<int>(t);
    int sp = m.bodies[body].first_spring;
    while (m.springs.type[sp] != t) ++sp;
    const SpringCoefficients base{m.springs.ks[sp], m.springs.kd[sp]};
    const std::string name(spring_type_name(t));
    check_derivative(
        c, g.ks[at], 1e-6 * base.ks,
        [&](Simulator& s, Real e) {
          s.set_spring_coefficients(body, t, {base.ks + e, base.kd});
        },
        name + ".ks");
    check_derivative(
        c, g.kd[at], 1e-4 * base.kd,
        [&](Simulator& s, Real e) {
          s.set_spring_coefficients(body, t, {base.ks, base.kd + e});
        },
        name + ".kd");
  }
  const Real mass = m.mass[m.bodies[body].first_particle];
  check_derivative(
      c, g.particle_mass[body], 1e-6 * mass,
      [&](Simulator& s, Real e) { s.set_particle_mass(body, mass + e); }, "mass");
  for (int d = 0; d < 3; ++d) {
    check_derivative(
        c, g.gravity[d], 1e-6,
        [&](Simulator& s, Real e) {
          Vec3 gravity = s.model().gravity;
          gravity[d] += e;
          s.set_gravity(gravity);
        },
        "gravity[" + std::to_string(d) + "]");
  }
  // The initial state and the pins' targets along random directions.
  const VecX dir_x = random_vector(m.num_dofs(), 11), dir_v = random_vector(m.num_dofs(), 12);
  check_derivative(
      c, g.initial_position.dot(dir_x), 1e-8,
      [&](Simulator& s, Real e) { s.mutable_state().x += e * dir_x; },  // (contacts kept)
      "initial positions");
  check_derivative(
      c, g.initial_velocity.dot(dir_v), 1e-7,
      [&](Simulator& s, Real e) { s.mutable_state().v += e * dir_v; }, "initial velocities");
  if (!c.targets.empty()) {
    const VecX dir = random_vector(3 * static_cast<int>(c.targets.size()), 13);
    Real adjoint = 0;
    for (size_t k = 0; k < c.targets.size(); ++k)
      adjoint += g.pin_targets[k].dot(dir.segment<3>(3 * k));
    check_derivative(c, adjoint, 1e-7, ProblemEdit([&](Simulator&, GradientProblem& p, Real e) {
                       for (size_t k = 0; k < p.pin_targets.size(); ++k)
                         p.pin_targets[k] += e * dir.segment<3>(3 * k);
                     }),
                     "pin targets");
  }
}

// A 6 x 6 cloth pinned at two corners, one of them driven along a sampled circle.
AdjointCase pinned_cloth(const std::string& integrator = "implicit_euler") {
  AdjointCase c;
  c.steps = 16;
  Model model;
  ClothShape cloth;
  cloth.nu = 6;
  cloth.nv = 6;
  cloth.pose.position = Vec3(0, 1.5, 0);
  BodySpec sheet;
  sheet.name = "sheet";
  sheet.shape = cloth;
  sheet.material.particle_mass = 0.05;
  sheet.material.springs[0] = {300, 2};
  sheet.material.springs[1] = {150, 1};
  sheet.material.springs[2] = {40, 0.5};
  sheet.pins = {PinSpec{{{}, false, {}, "corner_00"}, Path()},
                PinSpec{{{}, false, {}, "corner_10"}, Path()}};
  add_body(model, sheet, "bodies[0].");
  const int driven = model.pins.particles[1];
  const Vec3 start = particle(model.rest_position, driven);
  c.driven = {driven};
  for (int k = 0; k < c.steps; ++k) {
    const Real angle = 0.3 * (k + 1);
    c.targets.push_back(start + 0.1 * Vec3(std::sin(angle), 1 - std::cos(angle), 0.5 * angle));
  }
  c.make = [model, integrator] {
    return testing::make_sim(model, jittered(rest_state(model), 0.01, 0.1), integrator, 1.0 / 60);
  };
  return c;
}

// The external forces' parameters (vector, drag, gust of each force) against central
// differences of runs of the model with that parameter changed (the gust's step 1e-4: its
// gradients are small, and the loss is smooth enough in it for the O(step^2) error).
void check_external_forces(const std::function<AdjointCase(const Model&)>& make_case,
                           const Model& model) {
  const GradientResult g = gradient_of(make_case(model));
  ASSERT_EQ(g.force_vector.size(), model.external_forces.size());
  const auto difference = [&](Real eps, const std::function<void(ExternalForce&, Real)>& edit,
                              size_t e) {
    Model plus = model, minus = model;
    edit(plus.external_forces[e], eps);
    edit(minus.external_forces[e], -eps);
    const auto loss = [](const AdjointCase& c) {
      return run_loss(c, [](Simulator&, GradientProblem&) {});
    };
    return (loss(make_case(plus)) - loss(make_case(minus))) / (2 * eps);
  };
  for (size_t e = 0; e < model.external_forces.size(); ++e) {
    const ExternalForce& force = model.external_forces[e];
    const std::string name = "external_forces[" + std::to_string(e) + "] (" +
                             std::string(external_force_kind_name(force.kind)) + ")";
    for (int d = 0; d < 3; ++d) {
      expect_close(g.force_vector[e][d],
                   difference(
                       1e-6, [d](ExternalForce& f, Real eps) { f.vector[d] += eps; }, e),
                   kTolerance, name + ".vector[" + std::to_string(d) + "]");
    }
    expect_close(g.force_gust[e],
                 difference(
                     1e-4, [](ExternalForce& f, Real eps) { f.gust += eps; }, e),
                 kTolerance, name + ".gust");
    if (force.kind == ExternalForceKind::kWind) {
      expect_close(g.force_drag[e],
                   difference(
                       1e-6, [](ExternalForce& f, Real eps) { f.drag += eps; }, e),
                   kTolerance, name + ".drag");
    } else {
      EXPECT_EQ(g.force_drag[e], 0) << name;
    }
  }
}

// A constant force spread by mass over seven particles of a 3 x 3 x 3 cube, wind on its top
// layer (from `wind_start` s) and two point forces, all gusting: every parameter kind of the
// external forces.
std::vector<ExternalForce> gusting_forces(Real wind_start = 0) {
  ExternalForce push;
  push.kind = ExternalForceKind::kConstant;
  push.particles = {0, 1, 2, 5, 9, 13, 26};
  push.vector = Vec3(0.3, -0.2, 0.4);
  push.gust = 0.3;
  push.gust_frequency = 2;
  ExternalForce wind;
  wind.kind = ExternalForceKind::kWind;
  wind.particles = {18, 19, 20, 21, 22, 23, 24, 25, 26};
  wind.vector = Vec3(2, 0.5, -1);
  wind.drag = 0.05;
  wind.gust = 0.2;
  wind.gust_frequency = 3;
  wind.start = wind_start;
  ExternalForce point;
  point.kind = ExternalForceKind::kPoint;
  point.particles = {4, 22};
  point.vector = Vec3(-0.1, 0.2, 0.05);
  point.gust = -0.4;
  point.gust_frequency = 5;
  return {push, wind, point};
}

}  // namespace
}  // namespace jelly
