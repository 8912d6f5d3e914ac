// Contact with mesh obstacles: the restitution law on a fixed and on a moving mesh box for every
// integrator, a jelly resting in a bowl (no sinking, no jitter), implicit_euler's in-solve
// contact at a game's step, and the seed model's momentum exchange with a moving mesh.
#include <gtest/gtest.h>

#include <cmath>

#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/mesh_obstacle.hpp>

#include "support/meshes.hpp"
#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::make_sim;
using testing::max_speed;
using testing::min_distance;
using testing::single_particle;

class MeshEveryIntegrator : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Registry, MeshEveryIntegrator, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// A mesh obstacle from `mesh` written to `dir`.
std::unique_ptr<MeshObstacle> mesh_obstacle(const testing::MeshDir& dir, const TriangleMesh& mesh,
                                            const Vec3& position, const ContactParams& c,
                                            Path motion = {}) {
  MeshObstacleSpec s;
  s.file = dir.write("obstacle.stl", mesh);
  s.pose.position = position;
  s.motion = std::move(motion);
  return std::make_unique<MeshObstacle>(s, c);
}

// A particle dropped from 1 m onto a box mesh bounces back to e^2 of its height.
TEST_P(MeshEveryIntegrator, BounceOnAMeshBoxWithRestitution) {
  testing::MeshDir dir;
  const Model m = single_particle();
  State s = rest_state(m);
  s.x = Vec3(0.1, 1.25, -0.2);
  ContactParams c;
  c.restitution = 0.6;
  Simulator sim = make_sim(m, s, GetParam(), 1e-4);
  sim.add_terrain(mesh_obstacle(dir, box_mesh(Vec3(2, 0.5, 2)), Vec3::Zero(), c));
  Real apex = 0;
  bool bounced = false;
  testing::Probe probe([&](const Simulator& sm) {
    bounced = bounced || sm.state().v[1] > 0;
    if (bounced) apex = std::max(apex, sm.state().x[1] - 0.25);
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  EXPECT_NEAR(apex, 0.36, 0.36 * 0.01);
  EXPECT_NEAR(sim.state().x[0], 0.1, 1e-9);  // straight up and down
  EXPECT_NEAR(sim.state().x[2], -0.2, 1e-9);
}

// The box mesh rising at 1 m/s: the particle, released 1 m above its top, hits it with relative
// speed w = sqrt(1 + 2 g) and rises back to e^2 w^2 / (2 g) above it (the surface velocity
// enters the contact).
TEST_P(MeshEveryIntegrator, BounceOnAMovingMeshBoxKeepsTheRestitutionLaw) {
  testing::MeshDir dir;
  const Model m = single_particle();
  State s = rest_state(m);
  s.x = Vec3(0, 1.25, 0);
  ContactParams c;
  c.restitution = 0.6;
  Simulator sim = make_sim(m, s, GetParam(), 1e-4);
  sim.add_terrain(mesh_obstacle(dir, box_mesh(Vec3(2, 0.5, 2)), Vec3::Zero(), c,
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

// A jelly dropped into a bowl (inner radius 1 m) slides to its bottom and rests there: it never
// sinks more than 1 mm into the mesh, and in the end neither moves nor jitters. (For two explicit
// integrators at 1 ms and, below, implicit_euler at a game's step: a mesh query costs
// microseconds, docs/contact.md "What contact costs".)
class MeshBowl : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Explicit, MeshBowl, ::testing::Values("symplectic_euler", "rk4"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// Friction (mu_s = 0.5) holds the cube wherever the bowl is less steep than atan(0.5): its centre
// rests low in the bowl, within sin(atan(0.5)) = 0.45 of the axis.
void expect_at_the_bottom(const Vec3& com) {
  EXPECT_LT(std::hypot(com.x(), com.z()), 0.45 * 0.8);
  EXPECT_LT(com.y(), -0.7);
  EXPECT_GT(com.y(), -0.85);
}

TEST_P(MeshBowl, JellyRestsInTheBowl) {
  testing::MeshDir dir;
  const Model m = build_cube(testing::small_cube(4, 0.4, Vec3(-0.05, -0.8, -0.2)));
  Simulator sim = make_sim(m, rest_state(m), GetParam(), 1e-3, 0.01);
  sim.add_terrain(mesh_obstacle(dir, testing::bowl_mesh(1.0, 0.1), Vec3::Zero(), ContactParams{}));
  const Terrain& bowl = *sim.terrains()[0];
  const testing::RestWatch w = testing::run_watching_rest(sim, bowl, 3, 4.0);
  ASSERT_TRUE(w.report.ok());
  EXPECT_GE(w.deepest, -1e-3);
  EXPECT_LT(w.highest_late - w.lowest_late, 1e-3);
  EXPECT_LT(max_speed(sim.state()), 0.02);
  expect_at_the_bottom(center_of_mass(m, sim.state()));
}

// implicit_euler at 1/60 and 1/30 s resolves the bowl's contact inside its solve.
class MeshLargeSteps : public ::testing::TestWithParam<Real> {};
INSTANTIATE_TEST_SUITE_P(ImplicitEuler, MeshLargeSteps, ::testing::Values(1.0 / 60, 1.0 / 30),
                         [](const ::testing::TestParamInfo<Real>& p) {
                           return "dt1_" +
                                  std::to_string(static_cast<int>(std::round(1 / p.param)));
                         });

TEST_P(MeshLargeSteps, JellyRestsInTheBowl) {
  testing::MeshDir dir;
  const Model m = build_cube(testing::small_cube(4, 0.4, Vec3(-0.05, -0.8, -0.2)));
  Simulator sim = make_sim(m, rest_state(m), "implicit_euler", GetParam());
  sim.add_terrain(mesh_obstacle(dir, testing::bowl_mesh(1.0, 0.1), Vec3::Zero(), ContactParams{}));
  const Terrain& bowl = *sim.terrains()[0];
  Real deepest = 0, previous = total_energy(m, sim.state()), worst_growth = 0;
  const Real scale = std::abs(previous);
  Vec3 com_at_3 = Vec3::Zero();
  while (sim.state().t < 4.0 - 0.5 * GetParam()) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << r.message;
    deepest = std::min(deepest, min_distance(sim, bowl));
    const Real e = total_energy(m, sim.state());
    worst_growth = std::max(worst_growth, e - previous);
    previous = e;
    if (std::abs(sim.state().t - 3.0) < 0.5 * GetParam()) com_at_3 = center_of_mass(m, sim.state());
  }
  EXPECT_GE(deepest, -1e-3);
  EXPECT_LE(worst_growth, 1e-9 * scale);
  const Vec3 com = center_of_mass(m, sim.state());
  EXPECT_LT((com - com_at_3).norm(), 1e-3);
  expect_at_the_bottom(com);
}

// The seed model against a mesh box moving up at 3 m/s (infinite mass): the particle's normal
// velocity u1 becomes u2 + e (u2 - u1), its tangential one is kept.
TEST(SeedContactWithMesh, MovingMeshExchangeFormula) {
  testing::MeshDir dir;
  const Model m = single_particle();
  ContactParams c;
  c.model = ContactModel::kSeed;
  Terrains terrains;
  terrains.push_back(mesh_obstacle(dir, box_mesh(Vec3(2, 2, 2)), Vec3::Zero(), c,
                                   Path::keyframes({0, 10}, {Vec3::Zero(), Vec3(0, 30, 0)})));
  State s = rest_state(m);
  s.t = 1.0;                     // top face at y = 3 + 1
  s.x = Vec3(0.3, 4.005, -0.2);  // within epsilon = 0.01
  s.v = Vec3(-1.0, -2.0, 0.5);
  ContactSolver contacts;
  contacts.resolve(m, terrains, s, s, 1e-3);
  ASSERT_EQ(contacts.contact_count(), 1);
  const Real u1 = -2.0, u2 = 3.0, e = 0.8;
  EXPECT_NEAR(s.v[1], u2 + e * (u2 - u1), 1e-12);
  EXPECT_NEAR(s.v[0], -1.0, 1e-12);
  EXPECT_NEAR(s.v[2], 0.5, 1e-12);
}

}  // namespace
}  // namespace jelly
