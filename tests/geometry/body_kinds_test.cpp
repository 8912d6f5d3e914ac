// Body kinds: spring counts of the box and cloth lattices, closed and outward render surfaces,
// masses from a density, scene JSON round trips, and free fall of every registered kind.
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/box.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {
namespace {

// Volume enclosed by a closed surface (divergence theorem): positive when its triangles face
// outwards.
Real enclosed_volume(const Surface& s, const VecX& x) {
  Real v = 0;
  for (const Triangle& t : s.triangles) {
    v += s.vertex(x, t[0]).dot(s.vertex(x, t[1]).cross(s.vertex(x, t[2]))) / 6;
  }
  return v;
}

// Every edge of a closed, consistently oriented surface is used once in each direction.
bool closed_and_oriented(const Surface& s) {
  std::map<std::pair<int, int>, int> edges;
  for (const Triangle& t : s.triangles) {
    for (int e = 0; e < 3; ++e) ++edges[{t[e], t[(e + 1) % 3]}];
  }
  for (const auto& [edge, count] : edges) {
    if (count != 1) return false;
    const auto back = edges.find({edge.second, edge.first});
    if (back == edges.end() || back->second != 1) return false;
  }
  return true;
}

TEST(BoxShape, SpringCountsAndSurface) {
  BoxShape box;
  box.n = {3, 4, 5};
  box.size = Vec3(1, 2, 3);
  const BodyPart part = box.build(Material{}, "box.");
  const long nx = 3, ny = 4, nz = 5;
  EXPECT_EQ(part.num_particles(), nx * ny * nz);
  EXPECT_EQ(part.springs.count(SpringType::kStructural),
            (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1));
  EXPECT_EQ(part.springs.count(SpringType::kShear),
            2 * ((nx - 1) * (ny - 1) * nz + (nx - 1) * ny * (nz - 1) + nx * (ny - 1) * (nz - 1)) +
                4 * (nx - 1) * (ny - 1) * (nz - 1));
  EXPECT_EQ(part.springs.count(SpringType::kBending),
            (nx - 2) * ny * nz + nx * (ny - 2) * nz + nx * ny * (nz - 2));
  EXPECT_EQ(part.surface.num_triangles(),
            4 * ((nx - 1) * (ny - 1) + (nx - 1) * (nz - 1) + (ny - 1) * (nz - 1)));
  EXPECT_TRUE(closed_and_oriented(part.surface));
  EXPECT_NEAR(enclosed_volume(part.surface, part.position), 6.0, 1e-12);
  Model model;
  model.add_body("box", part);
  EXPECT_NEAR(center_of_mass(model, model.rest_position).norm(), 0, 1e-12);
}

TEST(BoxShape, IsTheCubeWhenItsSidesAreEqual) {
  const CubeSpec cube;  // the seed cube
  BoxShape box;
  box.n = {cube.n, cube.n, cube.n};
  box.size = Vec3::Constant(cube.edge_length);
  box.pose.position = cube.origin + Vec3::Constant(cube.edge_length / 2);
  const BodyPart a = box.build(cube.material(), "box.");
  const Model b = build_cube(cube);
  ASSERT_EQ(a.num_particles(), b.num_particles());
  EXPECT_LT((a.position - b.rest_position).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_EQ(a.springs.a, b.springs.a);
  EXPECT_EQ(a.springs.b, b.springs.b);
  EXPECT_EQ(a.springs.type, b.springs.type);
}

TEST(BoxShape, RotatedKeepsItsLengthsAndVolume) {
  BoxShape box;
  box.n = {3, 3, 4};
  box.size = Vec3(1, 1, 2);
  box.pose.rotation_degrees = Vec3(30, 45, 60);
  box.pose.position = Vec3(1, 2, 3);
  const BodyPart part = box.build(Material{}, "box.");
  EXPECT_NEAR(enclosed_volume(part.surface, part.position), 2.0, 1e-12);
  Real longest = 0;
  for (Real l : part.springs.rest_length) longest = std::max(longest, l);
  EXPECT_NEAR(longest, 4.0 / 3, 1e-12);  // bending along z: 2 x 2 / 3
}

TEST(Material, DensityGivesTheBodyItsMass) {
  Material m;
  m.density = 250;
  BoxShape box;
  box.n = {4, 5, 6};
  box.size = Vec3(0.5, 1, 1.5);
  EXPECT_NEAR(box.build(m, "box.").mass.sum(), 250 * 0.75, 1e-10);
  ClothShape cloth;
  cloth.nu = 7;
  cloth.nv = 4;
  cloth.size_u = 2;
  cloth.size_v = 0.5;
  m.density = 0.3;  // kg/m^2
  EXPECT_NEAR(cloth.build(m, "cloth.").mass.sum(), 0.3 * 1.0, 1e-12);
}

TEST(ClothShape, SpringCountsAndSurface) {
  ClothShape cloth;
  cloth.nu = 6;
  cloth.nv = 4;
  cloth.pose.rotation_degrees = Vec3(90, 0, 0);
  const BodyPart part = cloth.build(Material{}, "cloth.");
  const long nu = 6, nv = 4;
  EXPECT_EQ(part.num_particles(), nu * nv);
  EXPECT_EQ(part.springs.count(SpringType::kStructural), (nu - 1) * nv + nu * (nv - 1));
  EXPECT_EQ(part.springs.count(SpringType::kShear), 2 * (nu - 1) * (nv - 1));
  EXPECT_EQ(part.springs.count(SpringType::kBending), (nu - 2) * nv + nu * (nv - 2));
  EXPECT_EQ(part.surface.num_triangles(), 2 * (nu - 1) * (nv - 1));
  // The memory estimate's count is the built one (not the lattice's 13 per particle).
  EXPECT_EQ(cloth.estimated_springs(), static_cast<long>(part.springs.size()));
  cloth.nu = 2;
  cloth.nv = 3;
  EXPECT_EQ(cloth.estimated_springs(),
            static_cast<long>(cloth.build(Material{}, "cloth.").springs.size()));
  cloth.nu = 6;
  cloth.nv = 4;
  // Rotated 90 degrees about x: the sheet is vertical, its +y side now faces +z.
  const Surface& s = part.surface;
  const Triangle& t = s.triangles[0];
  const Vec3 n = (s.vertex(part.position, t[1]) - s.vertex(part.position, t[0]))
                     .cross(s.vertex(part.position, t[2]) - s.vertex(part.position, t[0]));
  EXPECT_GT(n.normalized().z(), 1 - 1e-12);
}

TEST(CubeShape, SurfaceIsTheClosedLatticeBoundary) {
  const Model m = build_cube(CubeSpec{});
  ASSERT_EQ(m.bodies.size(), 1u);
  const Body& b = m.bodies[0];
  EXPECT_EQ(b.name, "jelly");
  EXPECT_EQ(b.kind, "cube");
  EXPECT_EQ(b.surface.num_vertices(), 1000 - 512);
  EXPECT_EQ(b.surface.num_triangles(), 6 * 81 * 2);
  EXPECT_TRUE(closed_and_oriented(b.surface));
  EXPECT_NEAR(enclosed_volume(b.surface, m.rest_position), 64, 1e-10);
  EXPECT_NEAR(b.radius, 0.5 * 4.0 / 9, 1e-15);
}

// A small example of every registered kind, as a scene would give it.
std::string example_json(std::string_view kind) {
  if (kind == "cube") return R"({"kind": "cube", "n": 3, "edge_length": 0.5})";
  if (kind == "box")
    return R"({"kind": "box", "nx": 2, "ny": 3, "nz": 2, "size": [0.3, 0.6, 0.3]})";
  if (kind == "cloth") return R"({"kind": "cloth", "nu": 4, "nv": 3})";
  return "";
}

TEST(BodyKinds, EveryKindRoundTripsThroughJson) {
  for (const BodyKindInfo& kind : body_kinds()) {
    const std::string text = example_json(kind.name);
    if (text.empty()) continue;  // a kind that needs files has tests of its own
    SCOPED_TRACE(std::string(kind.name));
    const Json json = Json::parse(text);
    JsonFields f(json, "bodies[0]");
    const BodySpec spec = BodySpec::read(f);
    const Json written = spec.to_json();
    JsonFields g(written, "bodies[0]");
    EXPECT_EQ(BodySpec::read(g).to_json(), written);
  }
}

TEST(BodyKinds, FreeFallOfEveryKindIsExactWithRk4) {
  for (const BodyKindInfo& kind : body_kinds()) {
    const std::string text = example_json(kind.name);
    if (text.empty()) continue;
    SCOPED_TRACE(std::string(kind.name));
    const Json json = Json::parse(text);
    JsonFields f(json, "bodies[0]");
    Model model;
    add_body(model, BodySpec::read(f), "bodies[0].");
    Simulator sim(model, rest_state(model), make_integrator("rk4"), SimulatorOptions{0.001, 0, {}});
    const RunReport report = sim.run_until(0.5);
    ASSERT_TRUE(report.ok()) << report.brief();
    const VecX expected = model.rest_position +
                          VecX(0.5 * 0.5 * 0.5 * model.gravity.replicate(model.num_particles(), 1));
    EXPECT_LT((sim.state().x - expected).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(BodySpec, PinsAndForcesResolveTheirSelections) {
  const Json json = Json::parse(R"({"kind": "cloth", "name": "sheet", "nu": 5, "nv": 5,
    "pins": [{"group": "corner_00"}, {"indices": [24], "path": {"kind": "oscillation",
             "amplitude": [0, 0.1, 0], "frequency": 1}}],
    "forces": [{"kind": "wind", "velocity": [1, 0, 0], "drag": 0.1, "gust": 0.5,
                "gust_frequency": 2}]})");
  JsonFields f(json, "bodies[0]");
  Model model;
  add_body(model, BodySpec::read(f), "bodies[0].");
  ASSERT_EQ(model.pins.size(), 2);
  EXPECT_EQ(model.pins.particles[0], 0);
  EXPECT_EQ(model.pins.particles[1], 24);
  EXPECT_TRUE(model.pins.paths[model.pins.path[0]].is_fixed());
  EXPECT_EQ(model.pins.paths[model.pins.path[1]].kind(), PathKind::kOscillation);
  ASSERT_EQ(model.external_forces.size(), 1u);
  EXPECT_EQ(model.external_forces[0].particles.size(), 25u);
}

std::string body_error(const std::string& text) {
  try {
    const Json json = Json::parse(text);
    JsonFields f(json, "bodies[0]");
    Model model;
    add_body(model, BodySpec::read(f), "bodies[0].");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(BodySpec, PinsShareNoParticleAndChooseAtLeastOne) {
  // "indices": [] chose the whole body.
  EXPECT_THAT(body_error(R"({"kind": "cube", "n": 3, "pins": [{"indices": []}]})"),
              ::testing::StartsWith("bodies[0].pins[0].indices = [] is invalid: a list of at "
                                    "least one particle index"));
  EXPECT_THAT(body_error(R"({"kind": "cube", "n": 3,
                            "forces": [{"kind": "point", "force": [1, 0, 0], "indices": []}]})"),
              ::testing::StartsWith("bodies[0].forces[0].indices = [] is invalid"));
  // Two pins on particle 1: one path was kept silently.
  EXPECT_EQ(body_error(R"({"kind": "cube", "n": 3, "pins": [{"indices": [0, 1]},
              {"indices": [2, 1], "path": {"kind": "oscillation", "amplitude": [0, 0.1, 0],
               "frequency": 1}}]})"),
            "bodies[0].pins[1] = {\"indices\":[2,1]} is invalid: pins that share no particle "
            "(particle 1 of body \"jelly\" is also in bodies[0].pins[0]: give it one pin, one "
            "path)");
  EXPECT_THAT(body_error(R"({"kind": "cube", "n": 3, "pins": [{"indices": [26]},
              {"region": {"min": [-99, -99, -99], "max": [99, 99, 99]}}]})"),
              ::testing::HasSubstr("(particle 26 of body \"jelly\" is also in bodies[0].pins[0]"));
}

// Pinning a whole cloth of 1.44 million particles: the pins were added in quadratic time (minutes,
// beyond the test's time limit).
TEST(BodySpec, PinningAWholeLargeBodyIsNotQuadratic) {
  const Json json = Json::parse(R"({"kind": "cloth", "nu": 1200, "nv": 1200,
    "pins": [{"region": {"min": [-100, -100, -100], "max": [100, 100, 100]}}]})");
  JsonFields f(json, "bodies[0]");
  Model model;
  add_body(model, BodySpec::read(f), "bodies[0].");
  ASSERT_EQ(model.pins.size(), 1440000);
  for (int k = 0; k < model.pins.size(); ++k) ASSERT_EQ(model.pins.particles[k], k);
  EXPECT_TRUE(model.pins.all_fixed());
  model.pins.validate(model.num_particles());
}

TEST(BodySpec, BadInputNamesTheField) {
  EXPECT_EQ(body_error(R"({"kind": "cube", "n": 3, "pins": [{"indices": [27]}]})"),
            "bodies[0].pins[0].indices = 27 is invalid: particle indices of body \"jelly\" in "
            "[0, 27)");
  EXPECT_THAT(body_error(R"({"kind": "cube", "n": 3, "pins": [{"region": {"min": [9, 9, 9],
              "max": [10, 10, 10]}}]})"),
              ::testing::StartsWith("bodies[0].pins[0].region = {min: [9 9 9], max: [10 10 10]} "
                                    "is invalid: a box holding at least one particle"));
  EXPECT_THAT(body_error(R"({"kind": "cloth", "pins": [{"group": "top"}]})"),
              ::testing::HasSubstr("bodies[0].pins[0].group = \"top\" is invalid: a group of the "
                                   "body: one of corner_00"));
  EXPECT_EQ(body_error(R"({"kind": "box", "nx": 1})"),
            "bodies[0].nx = 1 is invalid: an integer in [2, 2000]");
  EXPECT_EQ(body_error(R"({"kind": "cloth", "size_u": -1})"),
            "bodies[0].size_u = -1 is invalid: a finite size > 0 (m)");
  EXPECT_EQ(body_error(R"({"kind": "cube", "name": "a/b"})"),
            "bodies[0].name = \"a/b\" is invalid: a name without '/' or '.' (it names an HDF5 "
            "group)");
  EXPECT_EQ(body_error(R"({"kind": "blob"})"),
            "bodies[0].kind = \"blob\" is invalid: one of \"box\", \"cloth\", \"cube\", "
            "\"tetmesh\", \"voxelized\"");
  EXPECT_EQ(body_error(R"({"kind": "cube", "forces": [{"kind": "wind", "velocity": [1, 0, 0]}]})"),
            "bodies[0].forces[0].drag is missing: it is required");
}

}  // namespace
}  // namespace jelly
