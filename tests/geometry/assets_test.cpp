// The project's own meshes (assets/, made by scripts/make_assets.py): closed, manifold, outward,
// of the solids' volumes; voxelized they hold the particles their volumes give and the torus
// keeps its hole; the bear's parts are vertex groups that pins select, and a pinned ear holds
// its mesh vertices to the last bit while the bear hangs from it.
#include <algorithm>
#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/detail/voxelized.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/simulator.hpp>

#include "geometry_support.hpp"

namespace jelly {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::input_error;
using testing::occupied;
using testing::TempDir;
using testing::write_text;

std::string asset(const std::string& name) {
  return std::string(JELLY_SOURCE_DIR) + "/assets/" + name;
}

TEST(Assets, ClosedManifoldOutwardWithTheSolidsVolumes) {
  // The torus (radii 0.3, 0.1) and the bowl (half a shell of radii 0.4, 0.36) exactly; the bear
  // as OpenCASCADE measured its union of spheres and capsules (0.00465668 m^3).
  const struct {
    const char* file;
    Real volume;
  } cases[] = {{"torus.obj", 2 * M_PI * M_PI * 0.3 * 0.01},
               {"bowl.obj", 2.0 / 3 * M_PI * (0.064 - 0.046656)},
               {"gummy_bear.obj", 0.00465668}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const MeshFile m = read_mesh(asset(c.file), "file");  // manifold, oriented, finite
    const MeshTopology topo = mesh_topology(m.mesh);
    EXPECT_TRUE(topo.closed());
    EXPECT_TRUE(topo.manifold());
    EXPECT_NEAR(m.mesh.enclosed_volume(), c.volume, 0.02 * c.volume);  // > 0: outwards
    EXPECT_LT(m.mesh.num_triangles(), 6000);
  }
}

TEST(Assets, VoxelizedTorusHasItsVolumeAndItsHole) {
  const TriangleMesh torus = read_mesh(asset("torus.obj"), "file").mesh;
  const Real h = 0.02;
  const LatticeGrid grid = voxelize(torus, h);
  const Real expected = 2 * M_PI * M_PI * 0.3 * 0.01 / (h * h * h);
  EXPECT_NEAR(occupied(grid), expected, 0.05 * expected);
  // Nothing within 0.18 m of the axis (the hole's radius is 0.2 m), everything within 0.08 m
  // of the tube's centre circle.
  int in_hole = 0, tube_missed = 0;
  for (int i = 0; i < grid.n[0]; ++i)
    for (int j = 0; j < grid.n[1]; ++j)
      for (int k = 0; k < grid.n[2]; ++k) {
        const Vec3 p = grid.position(i, j, k);
        const Real radial = std::hypot(p.x(), p.z());
        const bool inside = grid.is_occupied(i, j, k);
        in_hole += inside && radial < 0.18;
        tube_missed += !inside && std::hypot(radial - 0.3, p.y() - 0.1) < 0.08;
      }
  EXPECT_EQ(in_hole, 0);
  EXPECT_EQ(tube_missed, 0);
}

TEST(Assets, BearPartsAreGroupsAndItsVolumeIsFilled) {
  VoxelizedShape bear;
  bear.file = asset("gummy_bear.obj");
  bear.spacing = 0.015;
  bear.validate("bodies[0].");
  const BodyPart part = bear.build(Material{}, "bodies[0].");
  const Real expected = 0.00465668 / std::pow(bear.spacing, 3);
  EXPECT_NEAR(part.num_particles(), expected, 0.05 * expected);
  std::vector<std::string> names;
  for (const ParticleGroup& g : part.groups) {
    names.push_back(g.name);
    EXPECT_FALSE(g.particles.empty()) << g.name;
  }
  EXPECT_THAT(names, ElementsAre("arm_left", "arm_right", "belly", "ear_left", "ear_right", "head",
                                 "leg_left", "leg_right", "snout"));
}

// The bear hung by its left ear: the ear's mesh vertices stay where they are to the last bit
// while the rest of the bear sags; a group the mesh lacks is an error listing those it has.
TEST(Assets, APinnedVertexGroupHoldsItsVerticesExactly) {
  TempDir dir;
  const auto scene_with_pin = [&](const std::string& group) {
    return write_text(dir.file("hang.json"), R"({
      "bodies": [{"kind": "voxelized", "name": "bear", "file": ")" +
                                                 asset("gummy_bear.obj") + R"(",
                  "spacing": 0.03, "density": 1100,
                  "springs": {"structural": {"ks": 300, "kd": 1}, "shear": {"ks": 300, "kd": 1},
                              "bending": {"ks": 300, "kd": 1}},
                  "pins": [{"group": ")" + group +
                                                 R"("}]}],
      "integrator": {"name": "implicit_euler", "dt": 0.016666666666666666}, "duration": 1})");
  };
  EXPECT_EQ(input_error([&] { make_model(load_scene(scene_with_pin("tail"))); }),
            "bodies[0].pins[0].group = \"tail\" is invalid: a group of the body: one of "
            "arm_left, arm_right, belly, ear_left, ear_right, head, leg_left, leg_right, snout");

  Simulator sim = make_simulator(load_scene(scene_with_pin("ear_left")));
  const Body& body = sim.model().bodies[0];
  const MeshFile mesh = read_mesh(asset("gummy_bear.obj"), "file");
  const auto ear = std::find_if(mesh.groups.begin(), mesh.groups.end(),
                                [](const VertexGroup& g) { return g.name == "ear_left"; });
  ASSERT_NE(ear, mesh.groups.end());
  std::vector<Vec3> before;
  for (int v : ear->vertices) before.push_back(body.surface.vertex(sim.state().x, v));
  // The lowest vertex (a foot), far from the ear.
  int foot = 0;
  for (int v = 0; v < mesh.mesh.num_vertices(); ++v) {
    if (mesh.mesh.vertices[v].y() < mesh.mesh.vertices[foot].y()) foot = v;
  }
  const Vec3 foot_before = body.surface.vertex(sim.state().x, foot);
  ASSERT_TRUE(sim.run_until(0.5).ok());
  for (std::size_t k = 0; k < before.size(); ++k) {
    const Vec3 now = body.surface.vertex(sim.state().x, ear->vertices[k]);
    ASSERT_EQ(now, before[k]) << "ear vertex " << ear->vertices[k];
  }
  // The rest swings down and sags under it.
  EXPECT_LT(body.surface.vertex(sim.state().x, foot).y(), foot_before.y() - 1e-3);
}

}  // namespace
}  // namespace jelly
