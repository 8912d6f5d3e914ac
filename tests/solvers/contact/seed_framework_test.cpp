// The seed_framework contact model: the report's collision handler inside every force evaluation,
// on that evaluation's own state, as in the course framework (docs/contact.md).
#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

constexpr Real kG = 9.8;

// One particle of mass 1 (no springs) at height y over the floor y = 0, moving at vy.
Simulator particle_over_floor(const std::string& integrator, ContactModel contact_model, Real y,
                              Real vy, Real dt) {
  Model m;
  m.mass = VecX::Ones(1);
  m.rest_position = Vec3(0, y, 0);
  State s;
  s.x = Vec3(0, y, 0);
  s.v = Vec3(0, vy, 0);
  SimulatorOptions options;
  options.dt = dt;
  Simulator sim(m, s, make_integrator(integrator), options);
  ContactParams contact;
  contact.model = contact_model;  // restitution 0.8, friction 0.5, epsilon 0.01
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), contact));
  return sim;
}

// In the zone and approaching at the start of the step: the first evaluation reflects the
// step's own velocity (-1 -> 0.8) and the contact force cancels gravity, so explicit Euler moves
// with the reflected velocity and keeps it. The after-step seed model integrates first and
// reflects afterwards.
TEST(SeedFramework, ExplicitEulerReflectsInItsEvaluation) {
  const Real h = 1e-3, y0 = 0.005;
  Simulator framework =
      particle_over_floor("explicit_euler", ContactModel::kSeedFramework, y0, -1, h);
  ASSERT_TRUE(framework.step().ok);
  EXPECT_NEAR(framework.state().v[1], 0.8, 1e-15);
  EXPECT_NEAR(framework.state().x[1], y0 + 0.8 * h, 1e-15);

  Simulator after = particle_over_floor("explicit_euler", ContactModel::kSeed, y0, -1, h);
  ASSERT_TRUE(after.step().ok);
  EXPECT_NEAR(after.state().x[1], y0 - h, 1e-15);
  EXPECT_NEAR(after.state().v[1], 0.8 * (1 + kG * h), 1e-13);
}

// RK4: stage 1 reflects (a = 0 under the contact force); the later stages move away from the
// surface, see gravity only, and their velocities are what moves the position:
//   v1 = 0.8 + h/6 (0 - 2g - 2g - g),  x1 = x0 + h/6 (0.8 + 2*0.8 + 2 (0.8 - g h/2) + 0.8 - g h)
//                                          = x0 + h (0.8 - g h / 3).
TEST(SeedFramework, Rk4StagesUseTheirOwnReflectedVelocities) {
  const Real h = 1e-3, y0 = 0.005;
  Simulator sim = particle_over_floor("rk4", ContactModel::kSeedFramework, y0, -1, h);
  ASSERT_TRUE(sim.step().ok);
  EXPECT_NEAR(sim.state().v[1], 0.8 - 5 * kG * h / 6, 1e-14);
  EXPECT_NEAR(sim.state().x[1], y0 + h * (0.8 - kG * h / 3), 1e-15);
}

// Midpoint: outside the zone at the start, inside it at the half step. The half step's
// evaluation reflects v_mid and cancels gravity there, so the position moves with the reflected
// v_mid while the velocity keeps v0 + h * 0: the framework's semantics, not a physical bounce.
TEST(SeedFramework, MidpointReflectsTheHalfStep) {
  const Real h = 2e-3, y0 = 0.0115, v0 = -2;
  Simulator sim = particle_over_floor("midpoint", ContactModel::kSeedFramework, y0, v0, h);
  ASSERT_TRUE(sim.step().ok);
  const Real v_mid = v0 - kG * h / 2;  // at y0 + v0 h/2 = 0.0095 < epsilon
  EXPECT_NEAR(sim.state().x[1], y0 - 0.8 * v_mid * h, 1e-15);
  EXPECT_NEAR(sim.state().v[1], v0, 1e-15);
}

// Symplectic Euler and the friction: a particle sliding along the floor into it, in the zone:
// the reflection keeps v_t; the contact force cancels gravity, friction -mu N v_t with N = g.
TEST(SeedFramework, SymplecticEulerFrictionUsesTheNormalForce) {
  const Real h = 1e-3;
  Simulator sim =
      particle_over_floor("symplectic_euler", ContactModel::kSeedFramework, 0.005, -1, h);
  State s = sim.state();
  s.v[0] = 2;  // sliding along x
  sim.set_state(s);
  ASSERT_TRUE(sim.step().ok);
  EXPECT_NEAR(sim.state().v[0], 2 - h * 0.5 * kG * 2, 1e-13);
  EXPECT_NEAR(sim.state().v[1], 0.8, 1e-15);
}

// Away from the zone the model changes nothing: the same run as without terrain contact.
TEST(SeedFramework, InactiveOutsideTheZone) {
  for (const std::string name : {"explicit_euler", "midpoint", "rk4", "symplectic_euler"}) {
    Simulator framework = particle_over_floor(name, ContactModel::kSeedFramework, 1, -1, 1e-3);
    Simulator coulomb = particle_over_floor(name, ContactModel::kCoulomb, 1, -1, 1e-3);
    ASSERT_TRUE(framework.run_until(0.1).ok());
    ASSERT_TRUE(coulomb.run_until(0.1).ok());
    EXPECT_TRUE(framework.state().x == coulomb.state().x) << name;
    EXPECT_TRUE(framework.state().v == coulomb.state().v) << name;
  }
}

// A jelly dropped with the framework's rules lands and stays above the floor within a few
// epsilons, for every explicit integrator.
TEST(SeedFramework, JellyLandsWithEveryExplicitIntegrator) {
  for (const std::string name : {"explicit_euler", "midpoint", "rk4", "symplectic_euler"}) {
    const Model m = build_cube(testing::small_cube(3, 1.0, Vec3(0, 0.3, 0)));
    Simulator sim = testing::make_sim(m, rest_state(m), name, 2.5e-4, 0.01);
    ContactParams contact;
    contact.model = ContactModel::kSeedFramework;
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), contact));
    Real lowest = 1;
    testing::Probe probe([&](const Simulator& s) {
      for (int i = 0; i < s.model().num_particles(); ++i)
        lowest = std::min(lowest, particle(s.state().x, i).y());
    });
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(1.5).ok()) << name;
    EXPECT_GT(lowest, -0.03) << name;
    EXPECT_LT(center_of_mass(sim.model(), sim.state()).y(), 0.6) << name;  // it landed
  }
}

// Integrators whose force evaluations are not the framework's stages refuse the model: at
// add_terrain (naming the terrain) and, for a model switched afterwards, at the next step.
TEST(SeedFramework, ImplicitAndAdaptiveIntegratorsRefuseIt) {
  for (const std::string& name : integrator_names()) {
    if (integrator_supports_in_evaluation_contact(name)) continue;
    Simulator sim = particle_over_floor(name, ContactModel::kSeed, 1, 0, 1e-3);
    ContactParams framework;
    framework.model = ContactModel::kSeedFramework;
    try {
      sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), framework));
      ADD_FAILURE() << name << " accepted seed_framework";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("terrains[1].contact.model"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    Terrain& plane = const_cast<Terrain&>(*sim.terrains()[0]);
    plane.set_contact(framework);
    EXPECT_THROW(sim.step(), InputError) << name;
  }
  EXPECT_EQ(contact_model_from_name("seed_framework", "model"), ContactModel::kSeedFramework);
  EXPECT_EQ(contact_model_name(ContactModel::kSeedFramework), "seed_framework");
}

// The warning for seed rules at a step that crosses their zone: the seed slope at 1/60 s
// (fall of about 6 m, 10 m/s at impact) gets one naming the coulomb model; the report's 1 ms
// does not, nor does a coulomb terrain.
TEST(SeedFramework, LargeStepWarningNamesCoulomb) {
  const Model m = build_cube(CubeSpec{});
  const State s = rest_state(m);
  for (ContactModel model :
       {ContactModel::kSeed, ContactModel::kSeedFramework, ContactModel::kCoulomb}) {
    ContactParams contact;
    contact.model = model;
    Terrains terrains;
    terrains.push_back(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
    const auto large = seed_step_warnings(m, s, terrains, 1.0 / 60, 5);
    const auto small = seed_step_warnings(m, s, terrains, 1e-3, 5);
    EXPECT_TRUE(small.empty());
    if (model == ContactModel::kCoulomb) {
      EXPECT_TRUE(large.empty());
      continue;
    }
    ASSERT_EQ(large.size(), 1u);
    EXPECT_NE(large[0].find("terrains[0]"), std::string::npos) << large[0];
    EXPECT_NE(large[0].find("\"coulomb\""), std::string::npos) << large[0];
    EXPECT_EQ(seed_step_warnings(m, s, terrains, 0.0027, 5).size(), 1u);
  }
}

}  // namespace
}  // namespace jelly
