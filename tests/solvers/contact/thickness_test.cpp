// A body's thickness against terrains and obstacles (Body::thickness): a cloth keeps its contact
// radius from them by default, in every contact path (implicit_euler's solve, the after-step
// response of rk4, xpbd's projections, the seed rules, vbd's penalty), and a body with volume
// keeps 0 (the seed references stay the same bits); the scene key is validated.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/plane.hpp>
#include <jelly/terrain/terrain.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::make_sim;

// A 9 x 9 cloth of 1 m (spacing 1/8 m: contact radius 1/16 m), `height` above the origin.
Model cloth_model(Real height, std::optional<Real> thickness = std::nullopt) {
  ClothShape cloth;
  cloth.nu = cloth.nv = 9;
  cloth.pose.position = Vec3(0, height, 0);
  BodySpec spec;
  spec.name = "cloth";
  spec.shape = cloth;
  spec.material.particle_mass = 0.01;
  for (SpringCoefficients& s : spec.material.springs) s = {20, 0.05};
  spec.thickness = thickness;
  Model model;
  add_body(model, spec, "bodies[0].");
  return model;
}

std::unique_ptr<Terrain> sphere(Real radius, const Vec3& center) {
  ObstacleSpec s;
  s.geometry.shape = ObstacleShape::kSphere;
  s.geometry.radius = radius;
  s.center = center;
  ContactParams c;
  c.restitution = 0;
  c.friction = c.static_friction = 0.5;
  return std::make_unique<Obstacle>(s, c);
}

std::unique_ptr<Terrain> floor_plane() {
  ContactParams c;
  c.restitution = 0;
  c.friction = c.static_friction = 0.5;
  return std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), c);
}

Real step_for(const std::string& integrator) {
  return integrator == "implicit_euler" || integrator == "xpbd" ? 1.0 / 60 : 1e-3;
}

// The defaults: a cloth's thickness is its contact radius, a cube's 0; the scene key sets it.
TEST(Thickness, ClothKeepsItsRadiusAndVolumesNone) {
  const Model cloth = cloth_model(1);
  EXPECT_DOUBLE_EQ(cloth.bodies[0].radius, 1.0 / 16);
  EXPECT_EQ(cloth.bodies[0].thickness, cloth.bodies[0].radius);
  const Model set = cloth_model(1, 0.01);
  EXPECT_EQ(set.bodies[0].thickness, 0.01);
  const Model cube = build_cube(testing::small_cube(3, 0.6));
  EXPECT_EQ(cube.bodies[0].thickness, 0);
}

// A negative or non-finite thickness names the field; the key reads and writes back.
TEST(Thickness, SceneKeyIsValidated) {
  const auto read = [](const std::string& text) {
    const Json j = Json::parse(text);
    JsonFields f(j, "bodies[0]");
    return BodySpec::read(f);
  };
  const BodySpec spec = read(R"({"kind": "cloth", "thickness": 0.02})");
  ASSERT_TRUE(spec.thickness.has_value());
  EXPECT_EQ(*spec.thickness, 0.02);
  EXPECT_EQ(spec.to_json()["thickness"].get<Real>(), 0.02);
  EXPECT_FALSE(read(R"({"kind": "cloth"})").to_json().contains("thickness"));
  try {
    read(R"({"kind": "cloth", "thickness": -0.1})");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bodies[0].thickness = -0.1"), std::string::npos)
        << e.what();
  }
}

class ThicknessIntegrators : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Contact, ThicknessIntegrators,
                         ::testing::Values("implicit_euler", "rk4", "xpbd"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// A cloth dropped flat onto a floor comes to rest with every particle's centre at its thickness
// above it (to the solver's tolerance, 1e-6 m), never below.
TEST_P(ThicknessIntegrators, ClothRestsOnAPlaneAtItsThickness) {
  const Model model = cloth_model(0.2);
  const Real thickness = model.bodies[0].thickness;
  Simulator sim = make_sim(model, rest_state(model), GetParam(), step_for(GetParam()));
  sim.add_terrain(floor_plane());
  Real lowest_ever = 1e9;
  testing::Probe probe([&](const Simulator& s) {
    for (int i = 0; i < model.num_particles(); ++i)
      lowest_ever = std::min(lowest_ever, s.state().x[3 * i + 1]);
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(2.0).ok());
  Real lowest = 1e9, highest = -1e9;
  for (int i = 0; i < model.num_particles(); ++i) {
    lowest = std::min(lowest, sim.state().x[3 * i + 1]);
    highest = std::max(highest, sim.state().x[3 * i + 1]);
  }
  EXPECT_NEAR(lowest, thickness, 1e-6);
  EXPECT_NEAR(highest, thickness, 1e-6);
  EXPECT_GT(lowest_ever, thickness - 1e-6);
}

// A cloth dropped onto a sphere drapes over it: no particle's centre ever comes closer to the
// sphere than the thickness (less 1e-5 m: xpbd's friction moves a particle along the tangent
// plane, off the curved surface by the square of the move over the diameter), and those on top
// rest at it (to 1e-6 m).
TEST_P(ThicknessIntegrators, ClothRestsOnASphereAtItsThickness) {
  const Model model = cloth_model(0.7);
  const Real thickness = model.bodies[0].thickness;
  const Real radius = 0.3;
  Simulator sim = make_sim(model, rest_state(model), GetParam(), step_for(GetParam()));
  sim.add_terrain(sphere(radius, Vec3::Zero()));
  const auto closest = [&](const VecX& x) {
    Real d = 1e9;
    for (int i = 0; i < model.num_particles(); ++i) d = std::min(d, particle(x, i).norm() - radius);
    return d;
  };
  Real closest_ever = 1e9;
  testing::Probe probe(
      [&](const Simulator& s) { closest_ever = std::min(closest_ever, closest(s.state().x)); });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.5).ok());
  EXPECT_NEAR(closest(sim.state().x), thickness, 1e-6);
  EXPECT_GT(closest_ever, thickness - 1e-5);
  // The centre particle (4, 4) is on top of the sphere, its thickness above it.
  EXPECT_NEAR(particle(sim.state().x, 4 * 9 + 4).norm() - radius, thickness, 1e-6);
}

// The seed contact rules and vbd's penalty keep the thickness too (within their own tolerances:
// the seed rules' epsilon zone, the penalty's depth under gravity).
TEST(Thickness, SeedRulesAndVbdPenaltyKeepIt) {
  for (const ContactModel kind : {ContactModel::kSeed, ContactModel::kSeedFramework}) {
    const Model model = cloth_model(0.2);
    const Real thickness = model.bodies[0].thickness;
    Simulator sim = make_sim(model, rest_state(model), "rk4", 1e-3);
    ContactParams c;
    c.model = kind;
    c.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), c));
    ASSERT_TRUE(sim.run_until(1.0).ok());
    Real lowest = 1e9;
    for (int i = 0; i < model.num_particles(); ++i)
      lowest = std::min(lowest, sim.state().x[3 * i + 1]);
    EXPECT_GT(lowest, thickness - c.epsilon) << contact_model_name(kind);
    EXPECT_LT(lowest, thickness + c.epsilon) << contact_model_name(kind);
  }
  IntegratorOptions options;
  options.vbd.contact_hardness = 1e4;
  const Model model = cloth_model(0.2);
  const Real thickness = model.bodies[0].thickness;
  SimulatorOptions so;
  so.dt = 1.0 / 60;
  Simulator sim(model, rest_state(model), make_integrator("vbd", options), so);
  sim.add_terrain(floor_plane());
  ASSERT_TRUE(sim.run_until(1.0).ok());
  Real lowest = 1e9;
  for (int i = 0; i < model.num_particles(); ++i)
    lowest = std::min(lowest, sim.state().x[3 * i + 1]);
  EXPECT_GT(lowest, thickness - 1e-6);
  EXPECT_LT(lowest, thickness + 1e-3);
}

}  // namespace
}  // namespace jelly
