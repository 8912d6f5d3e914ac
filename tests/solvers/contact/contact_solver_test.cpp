#include <gtest/gtest.h>

#include <cmath>

#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::contact_dt;
using testing::cube_on_slope;
using testing::make_sim;
using testing::max_speed;
using testing::min_distance;
using testing::single_particle;

// Contact is applied after each step the same way for every integrator (docs/contact.md), so
// every registered integrator must pass the scene-level contact tests.
class ContactEveryIntegrator : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Registry, ContactEveryIntegrator, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// A jelly dropped on the floor comes to rest on it: it never sinks below it, and in the end it
// neither moves nor jitters.
TEST_P(ContactEveryIntegrator, DroppedJellyComesToRest) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(0, 0.5, 0)));
  Simulator sim = make_sim(m, rest_state(m), GetParam(), contact_dt(GetParam()), 0.01);
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
  const Terrain& floor = *sim.terrains()[0];
  const testing::RestWatch w = testing::run_watching_rest(sim, floor, 4, 5.0);
  ASSERT_TRUE(w.report.ok());
  EXPECT_GE(w.deepest, -1e-3);                      // never more than 1 mm below the floor
  EXPECT_LT(w.highest_late - w.lowest_late, 1e-3);  // no jitter in the last second
  EXPECT_LT(max_speed(sim.state()), 0.02);
  EXPECT_NEAR(center_of_mass(m, sim.state()).y(), 0.5, 0.05);  // resting, slightly sagged
}

// A particle dropped from 1 m bounces back to e^2 of its height.
TEST_P(ContactEveryIntegrator, BounceWithRestitution) {
  const Model m = single_particle();
  State s = rest_state(m);
  s.x[1] = 1.0;
  ContactParams c;
  c.restitution = 0.6;
  Simulator sim = make_sim(m, s, GetParam(), 1e-4);
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), c));
  Real apex = 0;
  bool bounced = false;
  testing::Probe probe([&](const Simulator& sm) {
    bounced = bounced || sm.state().v[1] > 0;
    if (bounced) apex = std::max(apex, sm.state().x[1]);
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.2).ok());
  EXPECT_NEAR(apex, 0.36, 0.36 * 0.01);
}

// mu > tan(20 deg): the jelly sticks.
TEST_P(ContactEveryIntegrator, SticksOnSlopeWhenFrictionHolds) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.friction = c.static_friction = 0.6;
  Simulator sim = make_sim(m, cube_on_slope(m, 20), GetParam(), contact_dt(GetParam()));
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), c)));
  ASSERT_TRUE(sim.run_until(0.5).ok());
  const Vec3 settled = center_of_mass(m, sim.state());
  ASSERT_TRUE(sim.run_until(2.0).ok());
  EXPECT_LT((center_of_mass(m, sim.state()) - settled).norm(), 5e-3);
  EXPECT_GE(min_distance(sim, *sim.terrains()[0]), -1e-3);
}

// mu < tan(20 deg): the jelly slides down with acceleration g (sin a - mu cos a).
TEST_P(ContactEveryIntegrator, SlidesOnSlopeWithCoulombAcceleration) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.friction = c.static_friction = 0.15;
  Simulator sim = make_sim(m, cube_on_slope(m, 20), GetParam(), contact_dt(GetParam()));
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), c)));
  const Real a = 20 * M_PI / 180;
  const Vec3 down_slope(std::cos(a), -std::sin(a), 0);
  const auto speed_along = [&] {
    return linear_momentum(m, sim.state()).dot(down_slope) / m.mass.sum();
  };
  ASSERT_TRUE(sim.run_until(0.5).ok());
  const Real v1 = speed_along();
  ASSERT_TRUE(sim.run_until(1.5).ok());
  const Real v2 = speed_along();
  const Real expected = 9.8 * (std::sin(a) - 0.15 * std::cos(a));
  EXPECT_NEAR(v2 - v1, expected, 0.03 * expected);
}

// A jelly resting on the elevator rides it: while the platform accelerates upwards, the jelly
// moves with it and stays on top of it.
TEST_P(ContactEveryIntegrator, RidesTheElevator) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(-0.5, 1.001, -0.5)));
  Simulator sim = make_sim(m, rest_state(m), GetParam(), contact_dt(GetParam()), 0.01);
  sim.add_terrain(std::make_unique<Elevator>());
  const auto& elevator = static_cast<const Elevator&>(*sim.terrains()[0]);
  Real worst_gap = 0;
  testing::Probe probe([&](const Simulator& s) {
    const Real gap = center_of_mass(m, s.state()).y() - elevator.height(s.state().t);
    if (s.state().t > 0.3) worst_gap = std::max(worst_gap, std::abs(gap - 0.5));
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.9).ok());
  const Real platform_v = elevator.surface_velocity(Vec3::Zero(), sim.state().t).y();
  EXPECT_NEAR(platform_v, 5.7, 1e-9);
  EXPECT_NEAR(linear_momentum(m, sim.state()).y() / m.mass.sum(), platform_v, 0.1);
  EXPECT_LT(worst_gap, 0.05);  // sags under 12.8 m/s^2 of effective gravity, never falls through
  EXPECT_GE(min_distance(sim, elevator), -1e-3);
}

// A particle outside the platform's footprint falls past it.
TEST(Elevator, ParticleOutsideFootprintFallsPast) {
  const Model m = single_particle();
  State s = rest_state(m);
  s.x = Vec3(3.0, 2.0, 0.0);
  Simulator sim = make_sim(m, s, "rk4", 1e-3);
  sim.add_terrain(std::make_unique<Elevator>());
  ASSERT_TRUE(sim.run_until(1.0).ok());
  EXPECT_NEAR(sim.state().x[1], 2.0 - 4.9, 1e-9);
}

// The seed contact model follows the report's formulas.
TEST(SeedContact, ReflectsOnThePlaneAndCancelsTheInwardForce) {
  const Model m = single_particle();
  ContactParams c;
  c.model = ContactModel::kSeed;
  State s = rest_state(m);
  s.x[1] = 0.005;  // within epsilon = 0.01
  s.v = Vec3(0.5, -2.0, 0.0);
  Terrains terrains;
  terrains.push_back(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), c));
  ContactSolver contacts;
  contacts.resolve(m, terrains, s, s, 1e-3);
  EXPECT_EQ(contacts.contact_count(), 1);
  EXPECT_NEAR(s.v[1], 0.8 * 2.0, 1e-15);  // -e u1
  EXPECT_NEAR(s.v[0], 0.5, 1e-15);        // tangential kept
  // Gravity pushes into the plane: the contact force cancels it, friction is -mu N v_t.
  VecX f = Vec3(0, -9.8, 0);
  VecX v = Vec3(0.5, 0.3, 0);
  contacts.add_forces(v, f);
  EXPECT_NEAR(f[1], 0.0, 1e-15);
  EXPECT_NEAR(f[0], -0.5 * 9.8 * 0.5, 1e-14);
}

TEST(SeedContact, ElevatorMomentumExchangeFormula) {
  const Model m = single_particle();
  ContactParams c;
  c.model = ContactModel::kSeed;
  ElevatorSpec spec;
  spec.mass = 3;
  State s = rest_state(m);
  s.t = 1.0;  // platform at y = 2.5, moving up at 3 m/s
  s.x = Vec3(0, 2.505, 0);
  s.v = Vec3(0, -2.0, 0);
  Terrains terrains;
  terrains.push_back(std::make_unique<Elevator>(spec, c));
  ContactSolver contacts;
  contacts.resolve(m, terrains, s, s, 1e-3);
  const Real u1 = -2, u2 = 3, m1 = 1, m2 = 3, e = 0.8;
  EXPECT_NEAR(s.v[1], (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2), 1e-14);
}

// The seed model keeps the seed jelly on the slope (no projection, but no sinking either).
TEST(SeedContact, SeedCubeStaysOnTheSlope) {
  CubeSpec spec = testing::small_cube(4);
  const Model m = build_cube(spec);
  ContactParams c;
  c.model = ContactModel::kSeed;
  Simulator sim = make_sim(m, cube_on_slope(m, 20), "rk4", 1e-3, 0.01);
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), c)));
  Real deepest = 0;
  testing::Probe probe(
      [&](const Simulator& s) { deepest = std::min(deepest, min_distance(s, *s.terrains()[0])); });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(2.0).ok());
  EXPECT_GT(deepest, -0.05);
}

// Every contact model named in the scene tables has its model in the registry, which answers
// with that kind; the places each acts are the documented ones (docs/contact.md).
TEST(ContactModels, EveryNamedModelIsRegisteredWithItsPlaces) {
  for (const auto& entry : contact_models()) {
    const TerrainContactModel& model = terrain_contact_model(entry.value);
    EXPECT_EQ(model.kind(), entry.value) << entry.name;
  }
  EXPECT_TRUE(terrain_contact_model(ContactModel::kCoulomb).constrains_solves());
  EXPECT_FALSE(terrain_contact_model(ContactModel::kCoulomb).acts_in_evaluation());
  EXPECT_FALSE(terrain_contact_model(ContactModel::kSeed).constrains_solves());
  EXPECT_FALSE(terrain_contact_model(ContactModel::kSeed).acts_in_evaluation());
  EXPECT_TRUE(terrain_contact_model(ContactModel::kSeedFramework).acts_in_evaluation());
}

// The seed model carries its contacts into the next step: after a resolve() that reflected a
// particle approaching the floor, the contact is listed with the terrain's friction.
TEST(ContactModels, TheSeedModelCarriesItsContactsIntoTheNextStep) {
  const Model model = testing::single_particle();  // at the origin
  Terrains terrains;
  ContactParams params;
  params.model = ContactModel::kSeed;
  params.friction = 0.3;
  terrains.push_back(std::make_unique<Plane>(Vec3(0, -0.005, 0), Vec3::UnitY(), params));
  const State before = rest_state(model);
  State state = before;
  state.v = Vec3(1, -2, 0);  // within epsilon (0.01 m) of the floor and approaching
  ContactSolver contacts;
  contacts.resolve(model, terrains, before, state, 1e-3);
  ASSERT_EQ(contacts.seed_contacts().size(), 1u);
  EXPECT_EQ(contacts.seed_contacts()[0].particle, 0);
  EXPECT_EQ(contacts.seed_contacts()[0].friction, 0.3);
  EXPECT_EQ(contacts.contact_count(), 1);
  EXPECT_NEAR(state.v[1], 2 * params.restitution, 1e-15);  // reflected: -e u1 on a fixed plane
}

}  // namespace
}  // namespace jelly
