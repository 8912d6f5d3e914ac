// Contact inside the implicit Euler solve (solvers/implicit_contact.hpp): the filtered system,
// and the scene-level contact behaviour at the large steps implicit Euler is for.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/detail/implicit_contact.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::cube_on_slope;
using testing::run_traced;

// A 3x3x3 cube 1 mm above the floor, falling at 1 m/s, and one step of 10 ms: the bottom layer
// must be stopped on the floor.
struct FallingCube {
  Model model = build_cube(testing::small_cube(3, 1.0, Vec3(0, 1e-3, 0)));
  State s0 = rest_state(model);
  Terrains terrains;
  Real h = 0.01;
  FallingCube() {
    for (int i = 0; i < model.num_particles(); ++i) s0.v[3 * i + 1] = -1;
    terrains.push_back(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
  }
};

TEST(ImplicitContact, FilteredSystemKeepsTheConstraintsAndUnfiltersExactly) {
  FallingCube c;
  const Model& m = c.model;
  const SpringJacobian jacobian(m);
  SparseMatrix a = jacobian.make_matrix();
  VecX f(m.num_dofs()), kv(m.num_dofs());
  compute_forces(m, c.s0.x, c.s0.v, f);
  jacobian.assemble_system(m, c.s0.x, c.s0.v, JacobianOptions{}, c.h, c.h * c.h, a, c.s0.v, kv);
  const VecX b = c.h * (f + c.h * kv);
  const SparseMatrix original = a;

  ImplicitContact contact;
  ASSERT_TRUE(contact.begin_step(m, c.terrains, c.s0, f, c.h));
  ASSERT_EQ(contact.contacts().size(), 9u);  // the bottom layer
  VecX rhs, z(m.num_dofs()), dv = VecX::Zero(m.num_dofs());
  contact.constrain(a, b, true, rhs, z, dv);

  // Still symmetric and positive definite; dv = y + z satisfies the constraints.
  const Eigen::MatrixXd dense(a);
  EXPECT_LT((dense - dense.transpose()).norm(), 1e-12 * dense.norm());
  const Eigen::LLT<Eigen::MatrixXd> llt(dense);
  ASSERT_EQ(llt.info(), Eigen::Success);
  dv = llt.solve(rhs) + z;
  for (const ImplicitContact::Contact& k : contact.contacts()) {
    const Vec3 x1 = particle(c.s0.x, k.particle) +
                    c.h * (particle(c.s0.v, k.particle) + particle(dv, k.particle));
    EXPECT_NEAR(x1.y(), 0.0, 1e-14);  // lands exactly on the floor
    EXPECT_EQ(k.mode, ImplicitContact::Mode::kStick);
  }
  // The unconstrained rows satisfy the original equations: (A dv - b)_i = 0 for free i.
  const VecX residual = Eigen::MatrixXd(original) * dv - b;
  Real worst_free = 0, pushed = 0;
  for (int i = 0; i < m.num_particles(); ++i) {
    const bool constrained = particle(c.s0.x, i).y() < 0.01;
    if (constrained)
      pushed += particle(residual, i).y();  // the floor's impulse on the bottom layer
    else
      worst_free = std::max(worst_free, particle(residual, i).norm());
  }
  EXPECT_LT(worst_free, 1e-10 * b.norm());
  EXPECT_GT(pushed, 0);
  // The floor stops the bottom layer and nothing else: no new contact, nobody pulled.
  EXPECT_FALSE(contact.update(c.terrains, b, dv, true, a));
  for (const ImplicitContact::Contact& k : contact.contacts()) EXPECT_GT(k.normal_impulse, 0);

  contact.unconstrain(a);
  for (int e = 0; e < a.nonZeros(); ++e) ASSERT_EQ(a.valuePtr()[e], original.valuePtr()[e]) << e;
}

// Restitution never adds energy: when the step lost less than the bounce would give back (here
// the step stored 0.4 of the 0.5 J in the spring), the bounce is scaled so that the energy at
// the end equals the energy at the start; with enough loss it is the full e V.
TEST(ImplicitContact, RestitutionIsBoundedByTheEnergyTheStepLost) {
  testing::TwoParticleSpring pair;  // 1 kg each, ks 100, rest length 1, no gravity
  pair.stretch = 0;
  const Model m = pair.model();
  Terrains wall;
  ContactParams c;
  c.restitution = 1.0;
  wall.push_back(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitX(), c));
  for (const Real stored : {0.4, 0.0}) {
    State s0;
    s0.x = VecX::Zero(6);
    s0.x[0] = 1e-3;
    s0.x[3] = 1 + 1e-3;
    s0.v = VecX::Zero(6);
    s0.v[0] = -1;  // particle 0 hits the wall at 1 m/s: 0.5 J
    const Real h = 0.01;
    ImplicitContact contact;
    ASSERT_TRUE(contact.begin_step(m, wall, s0, VecX::Zero(6), h));
    ASSERT_EQ(contact.contacts().size(), 1u);
    // An end state (as a solve could give) with particle 0 on the wall and `stored` J in the
    // spring.
    State s1 = s0;
    s1.t = h;
    s1.x[0] = 0;
    s1.x[3] = 1 + std::sqrt(2 * stored / pair.ks);
    s1.v[0] = -0.1;
    contact.finish(m, wall, s1, 1);
    const Real bounce = s1.v[0];
    const Real expected = std::sqrt(2 * std::min(0.5 - stored, 0.5));  // e V = 1 if affordable
    EXPECT_NEAR(bounce, expected, 1e-12) << stored;
    EXPECT_LE(total_energy(m, s1), total_energy(m, s0) + 1e-12) << stored;
    EXPECT_EQ(contact.counters().restitution_limited, stored > 0 ? 1 : 0);
  }
}

class LargeSteps : public ::testing::TestWithParam<Real> {};
INSTANTIATE_TEST_SUITE_P(ImplicitContact, LargeSteps, ::testing::Values(1.0 / 60, 1.0 / 30),
                         [](const ::testing::TestParamInfo<Real>& p) {
                           return "dt1_" +
                                  std::to_string(static_cast<int>(std::round(1 / p.param)));
                         });

// A lone particle lands exactly on the floor and bounces with restitution e (its approach speed
// is the one at the start of the landing step, so the apex is e^2 h only to O(g dt)).
TEST_P(LargeSteps, LoneParticleBouncesWithoutSinking) {
  Model m;
  m.mass = VecX::Constant(1, 1.0);
  m.rest_position = VecX::Zero(3);
  State s = rest_state(m);
  s.x[1] = 1.0;
  ContactParams c;
  c.restitution = 0.6;
  Simulator sim = testing::make_sim(m, s, "implicit_euler", GetParam());
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), c));
  Real apex = 0;
  bool bounced = false;
  while (sim.state().t < 1.2) {
    ASSERT_TRUE(sim.step().ok);
    ASSERT_GE(sim.state().x[1], -1e-12);
    bounced = bounced || sim.state().v[1] > 0;
    if (bounced) apex = std::max(apex, sim.state().x[1]);
  }
  EXPECT_NEAR(apex, 0.36, 0.36 * 0.25);
}

// A jelly dropped on the floor: the floor never lets it in, the energy never grows, and it comes
// to rest on the floor.
TEST_P(LargeSteps, DroppedJellyRestsOnTheFloor) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(0, 0.5, 0)));
  Simulator sim = testing::make_sim(m, rest_state(m), "implicit_euler", GetParam());
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
  const testing::EnergyTrace trace = run_traced(sim, 4.0);
  EXPECT_GE(trace.deepest, -1e-9);
  EXPECT_LE(trace.worst_growth, 1e-9 * trace.scale);
  const Vec3 com = center_of_mass(m, sim.state());
  const testing::EnergyTrace rest = run_traced(sim, 5.0);
  EXPECT_LT((center_of_mass(m, sim.state()) - com).norm(), 1e-3);
  EXPECT_LE(rest.worst_growth, 1e-9 * trace.scale);
  EXPECT_NEAR(com.y(), 0.5, 0.05);
  EXPECT_EQ(sim.contacts().contact_count(), 16);  // the bottom layer
}

// A 4x4x4 jelly lying on a 20 degree slope with friction mu (static and kinetic).
Simulator on_slope_with_friction(Real mu, Real dt) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.friction = c.static_friction = mu;
  Simulator sim = testing::make_sim(m, cube_on_slope(m, 20), "implicit_euler", dt);
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), c)));
  return sim;
}

// mu > tan(20 deg): the jelly sticks, without creeping.
TEST_P(LargeSteps, SticksOnSlopeWhenFrictionHolds) {
  Simulator sim = on_slope_with_friction(0.6, GetParam());
  const Model& m = sim.model();
  const testing::EnergyTrace settle = run_traced(sim, 0.5);
  const Vec3 settled = center_of_mass(m, sim.state());
  const testing::EnergyTrace rest = run_traced(sim, 2.0);
  EXPECT_LT((center_of_mass(m, sim.state()) - settled).norm(), 1e-3);
  EXPECT_GE(std::min(settle.deepest, rest.deepest), -1e-9);
  EXPECT_LE(std::max(settle.worst_growth, rest.worst_growth), 1e-9 * settle.scale);
}

// mu < tan(20 deg): the jelly slides down with acceleration g (sin a - mu cos a), losing energy.
TEST_P(LargeSteps, SlidesOnSlopeWithCoulombAcceleration) {
  Simulator sim = on_slope_with_friction(0.15, GetParam());
  const Model& m = sim.model();
  const Real a = 20 * M_PI / 180;
  const Vec3 down_slope(std::cos(a), -std::sin(a), 0);
  const auto speed_along = [&] {
    return linear_momentum(m, sim.state()).dot(down_slope) / m.mass.sum();
  };
  run_traced(sim, 0.5);
  const Real v1 = speed_along();
  const testing::EnergyTrace trace = run_traced(sim, 1.5);
  const Real expected = 9.8 * (std::sin(a) - 0.15 * std::cos(a));
  EXPECT_NEAR(speed_along() - v1, expected, 0.03 * expected);
  EXPECT_GE(trace.deepest, -1e-9);
  EXPECT_LE(trace.worst_growth, 1e-9 * trace.scale);
}

// The platform accelerates upwards; the jelly rides it, never inside it.
TEST_P(LargeSteps, RidesTheElevator) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(-0.5, 1.001, -0.5)));
  Simulator sim = testing::make_sim(m, rest_state(m), "implicit_euler", GetParam());
  sim.add_terrain(std::make_unique<Elevator>());
  const auto& elevator = static_cast<const Elevator&>(*sim.terrains()[0]);
  const testing::EnergyTrace trace = run_traced(sim, 1.9);
  EXPECT_GE(trace.deepest, -1e-9);
  const Real platform_v = elevator.surface_velocity(Vec3::Zero(), sim.state().t).y();
  EXPECT_NEAR(linear_momentum(m, sim.state()).y() / m.mass.sum(), platform_v, 0.1);
  const Real gap = center_of_mass(m, sim.state()).y() - elevator.height(sim.state().t);
  EXPECT_NEAR(gap, 0.5, 0.05);
}

// Newton's method keeps the contacts of the linearized solve and converges with them.
TEST(ImplicitContact, NewtonConvergesInContact) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.friction = c.static_friction = 0.15;
  IntegratorOptions o;
  o.implicit.newton_iterations = 10;
  o.implicit.newton_tolerance = 1e-10;
  Simulator sim(m, cube_on_slope(m, 20), make_integrator("implicit_euler", o),
                SimulatorOptions{1.0 / 60, 0, {}});
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), c)));
  const testing::EnergyTrace trace = run_traced(sim, 1.0);
  const Statistics st = sim.integrator().statistics();
  EXPECT_EQ(st.at("newton_not_converged"), 0);
  EXPECT_GE(trace.deepest, -1e-9);
  EXPECT_LE(trace.worst_growth, 1e-9 * trace.scale);
  const auto& ie = static_cast<const ImplicitEuler&>(sim.integrator());
  EXPECT_TRUE(ie.last_converged());
}

// The state a checkpoint stores round-trips; a state of another model is dropped (its warm
// start) or filtered (contacts beyond the model), and a malformed one is an InputError.
TEST(ImplicitContact, InternalStateRoundTripsAndIsChecked) {
  const FallingCube c;
  const ContactSolver contacts;
  const Dynamics dynamics(c.model, contacts, &c.terrains);
  ImplicitEuler first;
  State s = c.s0;
  ASSERT_TRUE(first.step(dynamics, s, c.h).ok);
  const std::vector<Real> saved = first.internal_state();
  ASSERT_EQ(saved[0], c.model.num_dofs());  // the warm start, then 5 numbers per contact
  EXPECT_EQ(saved.size(), 1 + c.model.num_dofs() + 5 * 9u);
  ImplicitEuler second;
  second.restore_internal_state(saved);
  EXPECT_EQ(second.internal_state(), saved);

  const Model bigger = build_cube(testing::small_cube(4, 1.0, Vec3(0, 1e-3, 0)));
  const Dynamics big(bigger, contacts, &c.terrains);
  ImplicitEuler other;
  State t = rest_state(bigger);
  ASSERT_TRUE(other.step(big, t, c.h).ok);
  other.restore_internal_state(saved);  // 3x3x3 warm start on a 4x4x4 cube
  EXPECT_TRUE(other.step(big, t, c.h).ok);
  EXPECT_TRUE(t.x.allFinite());

  EXPECT_THROW(other.restore_internal_state({-1.0}), InputError);
  EXPECT_THROW(other.restore_internal_state({2.5, 0, 0, 0}), InputError);
  EXPECT_THROW(other.restore_internal_state({0, 1, 0, 0}), InputError);  // 3 numbers of a contact
}

// "after_step" keeps the operator split of the explicit integrators (the Simulator resolves
// contact after the step); an unknown value names the field.
TEST(ImplicitContact, AfterStepOptionUsesTheSimulatorsResolve) {
  ImplicitEulerOptions o;
  o.contact = ImplicitContactMode::kAfterStep;
  const FallingCube c;
  const ContactSolver contacts;
  State s = c.s0;
  ImplicitEuler after_step(o);
  StepResult r = after_step.step(Dynamics(c.model, contacts, &c.terrains), s, c.h);
  ASSERT_TRUE(r.ok);
  EXPECT_FALSE(r.contact.terrains);
  // Stepped with a Dynamics that has no terrains, it has resolved nothing: finish_step() must
  // handle every terrain.
  ImplicitEuler alone;
  s = c.s0;
  r = alone.step(Dynamics(c.model, contacts), s, c.h);
  ASSERT_TRUE(r.ok);
  EXPECT_FALSE(r.contact.terrains);
  r = alone.step(Dynamics(c.model, contacts, &c.terrains), s, c.h);
  ASSERT_TRUE(r.ok);
  EXPECT_TRUE(r.contact.terrains);

  const Json penalty = Json::parse(R"({"contact": "penalty"})");
  JsonFields f(penalty, "integrator.options");
  try {
    ImplicitEulerOptions::read(f);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "integrator.options.contact = \"penalty\" is invalid: one of \"implicit\", "
              "\"after_step\"");
  }
}

}  // namespace
}  // namespace jelly
