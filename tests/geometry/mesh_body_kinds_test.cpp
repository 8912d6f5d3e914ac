// Every registered body kind: an example of it falls freely exactly as RK4 integrates a
// parabola, and its JSON reads back to the same body. A kind without an example here fails.
#include <map>

#include <gtest/gtest.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>

#include "geometry_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;
using Vec3i = Eigen::Vector3i;

// One small body of each kind, as a scene gives it (files relative to the test's folder).
const std::map<std::string, std::string>& examples() {
  static const std::map<std::string, std::string> e{
      {"box", R"({"kind": "box", "nx": 3, "ny": 2, "nz": 4, "size": [0.5, 0.3, 0.6],
                  "rotation_degrees": [0, 30, 10]})"},
      {"cloth", R"({"kind": "cloth", "nu": 5, "nv": 4, "rotation_degrees": [90, 0, 0]})"},
      {"cube", R"({"kind": "cube", "n": 3, "edge_length": 1})"},
      {"tetmesh", R"({"kind": "tetmesh", "file": "cube.msh", "scale": 0.5, "density": 1000,
                      "position": [0, 1, 0]})"},
      {"voxelized", R"({"kind": "voxelized", "file": "ball.ply", "spacing": 0.2, "scale": 2,
                        "rotation_degrees": [0, 0, 45]})"},
  };
  return e;
}

class EveryBodyKind : public ::testing::TestWithParam<std::string> {
 protected:
  BodySpec read(const std::string& text) {
    write_mesh(dir_.file("ball.ply"), sphere_mesh(0.5, 12, 24));
    // The unit cube in 6 tets around its diagonal, corner c at (c & 1, c >> 1 & 1, c >> 2 & 1).
    TetMesh cube;
    for (int c = 0; c < 8; ++c) cube.vertices.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    for (const auto& a : {Vec3i(1, 2, 4), Vec3i(1, 4, 2), Vec3i(2, 1, 4), Vec3i(2, 4, 1),
                          Vec3i(4, 1, 2), Vec3i(4, 2, 1)}) {
      cube.tets.push_back({0, a[0], a[0] + a[1], 7});
    }
    write_msh(dir_.file("cube.msh"), cube);
    const Json j = Json::parse(text);
    JsonFields f(j, "bodies[0]");
    f.set_base_directory(dir_.path().string());
    return BodySpec::read(f);
  }
  TempDir dir_;
};

std::vector<std::string> kind_names() {
  std::vector<std::string> names;
  for (const BodyKindInfo& k : body_kinds()) names.emplace_back(k.name);
  return names;
}

// Gravity only, springs at rest: x(t) = x0 + v0 t + g t^2 / 2, which RK4 integrates exactly.
TEST_P(EveryBodyKind, FreeFallIsExactForRk4) {
  const auto example = examples().find(GetParam());
  ASSERT_NE(example, examples().end()) << "add an example of body kind " << GetParam();
  Model model;
  add_body(model, read(example->second), "bodies[0].");
  ASSERT_GE(model.num_particles(), 8);
  ASSERT_GT(model.springs.size(), 0);
  State s = rest_state(model);
  const Vec3 v0(0.5, 3, -1);
  for (int i = 0; i < model.num_particles(); ++i) particle(s.v, i) = v0;
  SimulatorOptions options;
  options.dt = 0.002;
  Simulator sim(model, s, make_integrator("rk4"), options);
  ASSERT_TRUE(sim.run_until(0.5).ok());
  const Real t = sim.state().t;
  for (int i = 0; i < model.num_particles(); ++i) {
    const Vec3 exact = Vec3(particle(s.x, i)) + v0 * t + 0.5 * model.gravity * t * t;
    ASSERT_LT((Vec3(particle(sim.state().x, i)) - exact).norm(), 1e-10) << "particle " << i;
    ASSERT_LT((Vec3(particle(sim.state().v, i)) - (v0 + model.gravity * t)).norm(), 1e-10);
  }
  // Its surface moved with it.
  const Body& body = model.bodies[0];
  ASSERT_FALSE(body.surface.empty());
  for (int v = 0; v < body.surface.num_vertices(); ++v) {
    const Vec3 shift = v0 * t + 0.5 * model.gravity * t * t;
    EXPECT_LT((body.surface.vertex(sim.state().x, v) - body.surface.vertex(s.x, v) - shift).norm(),
              1e-10);
  }
}

TEST_P(EveryBodyKind, JsonReadsBackToTheSameBody) {
  const BodySpec spec = read(examples().at(GetParam()));
  const Json written = spec.to_json();
  JsonFields f(written, "bodies[0]");
  const BodySpec again = BodySpec::read(f);
  EXPECT_EQ(again.to_json(), written);
  Model a, b;
  add_body(a, spec, "");
  add_body(b, again, "");
  EXPECT_EQ(a.rest_position, b.rest_position);
  EXPECT_EQ(a.springs.a, b.springs.a);
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryBodyKind, ::testing::ValuesIn(kind_names()),
                         [](const auto& p) { return p.param; });

}  // namespace
}  // namespace jelly
