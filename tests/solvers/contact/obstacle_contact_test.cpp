// Contact with obstacles (sphere, box, capsule, cylinder), for every integrator: restitution on a
// curved and on a moving surface, a jelly resting on a box, Coulomb sliding down a tilted box,
// and the seed model's momentum exchange with a moving obstacle.
#include <gtest/gtest.h>

#include <cmath>

#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/obstacle.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::contact_dt;
using testing::make_sim;
using testing::max_speed;
using testing::min_distance;
using testing::run_traced;
using testing::single_particle;

class ObstacleEveryIntegrator : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Registry, ObstacleEveryIntegrator, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

std::unique_ptr<Obstacle> sphere(Real radius, const Vec3& center, const ContactParams& c) {
  ObstacleSpec s;
  s.geometry.shape = ObstacleShape::kSphere;
  s.geometry.radius = radius;
  s.center = center;
  return std::make_unique<Obstacle>(s, c);
}

std::unique_ptr<Obstacle> box(const Vec3& size, const Vec3& center, const ContactParams& c,
                              Real tilt_degrees = 0, Path motion = {}) {
  ObstacleSpec s;
  s.geometry.shape = ObstacleShape::kBox;
  s.geometry.size = size;
  s.center = center;
  s.rotation_degrees = Vec3(0, 0, -tilt_degrees);
  s.motion = std::move(motion);
  return std::make_unique<Obstacle>(s, c);
}

// A particle dropped from 1 m onto the top of a sphere bounces back to e^2 of its height.
TEST_P(ObstacleEveryIntegrator, BounceOnASphereWithRestitution) {
  const Model m = single_particle();
  State s = rest_state(m);
  s.x = Vec3(0, 1.5, 0);
  ContactParams c;
  c.restitution = 0.6;
  Simulator sim = make_sim(m, s, GetParam(), 1e-4);
  sim.add_terrain(sphere(0.5, Vec3::Zero(), c));
  Real apex = 0;
  bool bounced = false;
  testing::Probe probe([&](const Simulator& sm) {
    bounced = bounced || sm.state().v[1] > 0;
    if (bounced) apex = std::max(apex, sm.state().x[1] - 0.5);
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.2).ok());
  EXPECT_NEAR(apex, 0.36, 0.36 * 0.01);
  EXPECT_NEAR(sim.state().x[0], 0.0, 1e-9);  // straight up and down through the pole
}

// A box rising at 1 m/s: in its (inertial) frame the particle, released 1 m above the top, hits
// it with relative speed w = sqrt(1 + 2 g) and rises back to e^2 w^2 / (2 g) above it.
TEST_P(ObstacleEveryIntegrator, BounceOnAMovingBoxKeepsTheRestitutionLaw) {
  const Model m = single_particle();
  State s = rest_state(m);
  s.x = Vec3(0, 1.25, 0);
  ContactParams c;
  c.restitution = 0.6;
  Simulator sim = make_sim(m, s, GetParam(), 1e-4);
  sim.add_terrain(box(Vec3(2, 0.5, 2), Vec3::Zero(), c, 0,
                      Path::keyframes({0, 100}, {Vec3::Zero(), Vec3(0, 100, 0)})));
  const auto top = [](Real t) { return 0.25 + t; };
  Real apex = 0;
  bool bounced = false;
  testing::Probe probe([&](const Simulator& sm) {
    bounced = bounced || sm.state().v[1] > 1.0;
    if (bounced) apex = std::max(apex, sm.state().x[1] - top(sm.state().t));
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  const Real g = 9.8, w2 = 1 + 2 * g * 1.0;
  const Real expected = 0.36 * w2 / (2 * g);
  EXPECT_NEAR(apex, expected, expected * 0.01);
}

// A jelly dropped onto a box comes to rest on it: it never sinks more than 1 mm into it, and in
// the end neither moves nor jitters.
TEST_P(ObstacleEveryIntegrator, JellyRestsOnABox) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(-0.5, 0.5, -0.5)));
  Simulator sim = make_sim(m, rest_state(m), GetParam(), contact_dt(GetParam()), 0.01);
  sim.add_terrain(box(Vec3(3, 1, 3), Vec3(0, -0.5, 0), ContactParams{}));
  const Terrain& table = *sim.terrains()[0];
  const testing::RestWatch w = testing::run_watching_rest(sim, table, 4, 5.0);
  ASSERT_TRUE(w.report.ok());
  EXPECT_GE(w.deepest, -1e-3);
  EXPECT_LT(w.highest_late - w.lowest_late, 1e-3);
  EXPECT_LT(max_speed(sim.state()), 0.02);
  EXPECT_NEAR(center_of_mass(m, sim.state()).y(), 0.5, 0.05);
}

// The top face of a box tilted by 20 degrees is the seed slope: with mu < tan(20 deg) the jelly
// slides down it with acceleration g (sin a - mu cos a).
TEST_P(ObstacleEveryIntegrator, SlidesDownATiltedBoxWithCoulombAcceleration) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.friction = c.static_friction = 0.15;
  const Real a = 20 * M_PI / 180;
  const Vec3 n(std::sin(a), std::cos(a), 0);
  Simulator sim = make_sim(m, testing::cube_on_slope(m, 20), GetParam(), contact_dt(GetParam()));
  sim.add_terrain(box(Vec3(20, 1, 4), -0.5 * n, c, 20));  // top face through the origin
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
  EXPECT_GE(min_distance(sim, *sim.terrains()[0]), -1e-3);
}

// A jelly dropped onto a capsule and a cylinder lying side by side under it stays out of both.
TEST_P(ObstacleEveryIntegrator, JellyStaysOutOfCurvedObstacles) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(-0.5, 0.6, -0.5)));
  Simulator sim = make_sim(m, rest_state(m), GetParam(), contact_dt(GetParam()), 0.01);
  ObstacleSpec capsule;
  capsule.geometry.shape = ObstacleShape::kCapsule;
  capsule.geometry.radius = 0.2;
  capsule.geometry.height = 2;
  capsule.center = Vec3(0, 0.3, -0.3);
  capsule.rotation_degrees = Vec3(0, 0, 90);  // axis along x
  ObstacleSpec cylinder = capsule;
  cylinder.geometry.shape = ObstacleShape::kCylinder;
  cylinder.center = Vec3(0, 0.3, 0.3);
  sim.add_terrain(std::make_unique<Obstacle>(capsule));
  sim.add_terrain(std::make_unique<Obstacle>(cylinder));
  Real deepest = 0;
  testing::Probe probe([&](const Simulator& s) {
    for (const auto& t : s.terrains()) deepest = std::min(deepest, min_distance(s, *t));
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  EXPECT_GE(deepest, -1e-3);
  // Held up by them: its centre of mass stays above their tops (y = 0.5).
  EXPECT_GT(center_of_mass(m, sim.state()).y(), 0.5);
}

// implicit_euler at a game's time step resolves obstacle contact inside its solve: the normal and
// the distance are linearized at the start of the step, so on a curved surface a particle ends a
// step off it by the curvature's O((h v_t)^2 / R); the jelly still never sinks 1 mm, its energy
// never grows, and it comes to rest.
class ObstacleLargeSteps : public ::testing::TestWithParam<Real> {};
INSTANTIATE_TEST_SUITE_P(ImplicitEuler, ObstacleLargeSteps, ::testing::Values(1.0 / 60, 1.0 / 30),
                         [](const ::testing::TestParamInfo<Real>& p) {
                           return "dt1_" +
                                  std::to_string(static_cast<int>(std::round(1 / p.param)));
                         });

TEST_P(ObstacleLargeSteps, JellyDroppedOnASphereComesToRestOnIt) {
  const Model m = build_cube(testing::small_cube(4, 1.0, Vec3(-0.5, 2.2, -0.5)));
  Simulator sim = make_sim(m, rest_state(m), "implicit_euler", GetParam());
  ContactParams c;
  c.friction = c.static_friction = 0.8;
  sim.add_terrain(sphere(2.0, Vec3::Zero(), c));
  const testing::EnergyTrace trace = run_traced(sim, 3.0);
  EXPECT_GE(trace.deepest, -1e-3);
  EXPECT_LE(trace.worst_growth, 1e-9 * trace.scale);
  const Vec3 com = center_of_mass(m, sim.state());
  const testing::EnergyTrace rest = run_traced(sim, 4.0);
  EXPECT_GE(rest.deepest, -1e-3);
  EXPECT_LT((center_of_mass(m, sim.state()) - com).norm(), 1e-3);
  EXPECT_GT(com.y(), 2.2);  // on top of the sphere
}

TEST_P(ObstacleLargeSteps, SlidesDownATiltedBoxWithCoulombAcceleration) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.friction = c.static_friction = 0.15;
  const Real a = 20 * M_PI / 180;
  const Vec3 n(std::sin(a), std::cos(a), 0);
  Simulator sim = make_sim(m, testing::cube_on_slope(m, 20), "implicit_euler", GetParam());
  sim.add_terrain(box(Vec3(20, 1, 4), -0.5 * n, c, 20));
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

// The seed model against a sphere moving up at 3 m/s (infinite mass): the particle's normal
// velocity u1 becomes u2 + e (u2 - u1) along the sphere's normal, its tangential one is kept.
TEST(SeedContactWithObstacle, MovingSphereExchangeFormula) {
  const Model m = single_particle();
  ContactParams c;
  c.model = ContactModel::kSeed;
  ObstacleSpec spec;
  spec.geometry.shape = ObstacleShape::kSphere;
  spec.geometry.radius = 1;
  spec.motion = Path::keyframes({0, 10}, {Vec3::Zero(), Vec3(0, 30, 0)});
  State s = rest_state(m);
  s.t = 1.0;  // centre at (0, 3, 0)
  const Vec3 n = Vec3(1, 1, 0).normalized();
  s.x = Vec3(0, 3, 0) + 1.005 * n;  // within epsilon = 0.01
  s.v = Vec3(-1.0, -2.0, 0.5);
  Terrains terrains;
  terrains.push_back(std::make_unique<Obstacle>(spec, c));
  ContactSolver contacts;
  contacts.resolve(m, terrains, s, s, 1e-3);
  ASSERT_EQ(contacts.contact_count(), 1);
  const Real u1 = Vec3(-1.0, -2.0, 0.5).dot(n), u2 = Vec3(0, 3, 0).dot(n), e = 0.8;
  EXPECT_NEAR(particle(s.v, 0).dot(n), u2 + e * (u2 - u1), 1e-12);
  const Vec3 vt = Vec3(-1.0, -2.0, 0.5) - u1 * n;
  EXPECT_LT((particle(s.v, 0) - particle(s.v, 0).dot(n) * n - vt).norm(), 1e-12);
}

// The seed model keeps a seed jelly on a tilted box (no projection, but no sinking either).
TEST(SeedContactWithObstacle, SeedCubeStaysOnATiltedBox) {
  const Model m = build_cube(testing::small_cube(4));
  ContactParams c;
  c.model = ContactModel::kSeed;
  const Real a = 20 * M_PI / 180;
  Simulator sim = make_sim(m, testing::cube_on_slope(m, 20), "rk4", 1e-3, 0.01);
  sim.add_terrain(box(Vec3(20, 1, 4), -0.5 * Vec3(std::sin(a), std::cos(a), 0), c, 20));
  Real deepest = 0;
  testing::Probe probe(
      [&](const Simulator& s) { deepest = std::min(deepest, min_distance(s, *s.terrains()[0])); });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(2.0).ok());
  EXPECT_GT(deepest, -0.05);
}

}  // namespace
}  // namespace jelly
