// Obstacle kind "mesh": placement (scale, rotation, position), motion and spin against the
// analytic box obstacle, the scene's JSON (file relative to the scene's folder, round trip) and
// bad input (missing, open, degenerate meshes, NaN).
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/mesh_obstacle.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

#include "support/errors.hpp"
#include "support/meshes.hpp"

namespace jelly {
namespace {

using testing::error_of;

// A mesh obstacle and the box obstacle it should equal: a unit-cube mesh scaled by 0.5 is a box
// of edge 0.5, turned, placed, moving and spinning like the box.
TEST(MeshObstacle, PlacedMovingAndSpinningLikeTheAnalyticBox) {
  testing::MeshDir dir;
  MeshObstacleSpec mesh;
  mesh.file = dir.write("cube.stl", box_mesh(Vec3(1, 1, 1)));
  mesh.pose.scale = 0.5;
  mesh.pose.position = Vec3(0.3, -0.2, 1.0);
  mesh.pose.rotation_degrees = Vec3(10, 20, 30);
  mesh.motion = Path::keyframes({0, 2}, {Vec3::Zero(), Vec3(2, 0, -1)});
  mesh.angular_velocity_degrees = Vec3(0, 45, 10);
  ObstacleSpec box;
  box.geometry.shape = ObstacleShape::kBox;
  box.geometry.size = Vec3(0.5, 0.5, 0.5);
  box.center = mesh.pose.position;
  box.rotation_degrees = mesh.pose.rotation_degrees;
  box.motion = mesh.motion;
  box.angular_velocity_degrees = mesh.angular_velocity_degrees;
  const MeshObstacle a(mesh);
  const Obstacle b(box);
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1.5, 1.5);
  for (int k = 0; k < 500; ++k) {
    const Real t = 0.002 * k;
    const Vec3 p = b.position(t) + 0.5 * Vec3(u(rng), u(rng), u(rng));
    ASSERT_NEAR(a.signed_distance(p, t), b.signed_distance(p, t), 1e-12) << p.transpose();
    EXPECT_NEAR((a.position(t) - b.position(t)).norm(), 0.0, 1e-15);
    EXPECT_LT((a.pose(t).matrix() - b.pose(t).matrix()).norm(), 1e-12);
    const Real d = b.signed_distance(p, t);
    const Vec3 closest = a.closest_point(p, t);
    EXPECT_NEAR(b.signed_distance(closest, t), 0.0, 1e-12);
    EXPECT_NEAR((p - closest).norm(), std::abs(d), 1e-12);
    // The normal and the surface velocity where the nearest face is unique (the box's normal
    // picks one face on the ridges inside).
    const Vec3 q = b.rotation(t).transpose() * (p - b.position(t));
    Vec3 gap = (q.cwiseAbs() - Vec3::Constant(0.25)).eval();
    std::sort(gap.data(), gap.data() + 3);
    if (d < 0 && gap[2] - gap[1] < 1e-6) continue;
    EXPECT_LT((a.normal(p, t) - b.normal(p, t)).norm(), 1e-9) << p.transpose();
    EXPECT_LT((a.surface_velocity(p, t) - b.surface_velocity(p, t)).norm(), 1e-9);
  }
  EXPECT_EQ(a.kind(), "mesh");
  EXPECT_TRUE(a.can_contact(Vec3(5, 5, 5), 0));
  EXPECT_EQ(a.render_mesh().num_triangles(), 12);
}

// The scene's keys: the file relative to the scene's folder, written back with every key, the
// copies share the mesh; the kind is in the registry.
TEST(MeshObstacle, SceneJsonRoundTrip) {
  testing::MeshDir dir;
  dir.write("bowl.obj", testing::bowl_mesh(1.0, 0.1));
  const Json j = Json::parse(R"({"kind": "mesh", "file": "bowl.obj", "scale": 2,
      "position": [0, 1, 0], "rotation_degrees": [0, 90, 0],
      "motion": {"kind": "oscillation", "amplitude": [0, 0.1, 0], "frequency": 1},
      "angular_velocity_degrees": [0, 30, 0], "contact": {"model": "coulomb", "friction": 0.7, "static_friction": 0.8}})");
  const auto spec = read_terrain_spec(j, "terrains[0]", dir.path().string());
  const auto& m = dynamic_cast<const MeshObstacleSpec&>(*spec);
  EXPECT_EQ(m.file, dir.file("bowl.obj"));
  EXPECT_EQ(m.pose.scale, 2);
  EXPECT_EQ(spec->contact.friction, 0.7);
  const Json back = terrain_spec_json(*spec);
  EXPECT_EQ(back["file"], dir.file("bowl.obj"));
  const auto again = read_terrain_spec(back, "terrains[0]");
  EXPECT_EQ(terrain_spec_json(*again), back);
  const auto copy = spec->clone();
  EXPECT_EQ(dynamic_cast<const MeshObstacleSpec&>(*copy).shape(), m.shape());  // shared
  const auto terrain = spec->make();
  // Inside the bowl's wall at its bottom (scaled by 2, raised by 1): the wall is 0.2 thick.
  EXPECT_NEAR(terrain->signed_distance(Vec3(0, 1 - 2.1, 0), 0), -0.1, 2e-3);
  // Above the inner bottom: 1 from the sphere of radius 2 the inside follows (to the chords).
  EXPECT_NEAR(terrain->signed_distance(Vec3(0, 0, 0), 0), 1.0, 3e-3);
  EXPECT_LT((terrain->normal(Vec3(0, 0, 0), 0) - Vec3::UnitY()).norm(), 0.1);
  const auto attributes = terrain->attributes();
  ASSERT_EQ(attributes.size(), 4u);
  EXPECT_EQ(attributes[0].first, "scale");
  bool listed = false;
  for (const TerrainKindInfo& k : terrain_kinds()) listed = listed || k.name == "mesh";
  EXPECT_TRUE(listed);
}

TEST(MeshObstacle, BadInputNamesTheField) {
  testing::MeshDir dir;
  const auto read = [&](const std::string& text) {
    return error_of(
        [&] { read_terrain_spec(Json::parse(text), "terrains[1]", dir.path().string()); });
  };
  dir.write("box.obj", box_mesh(Vec3(1, 1, 1)));
  EXPECT_NE(
      read(R"({"kind": "mesh", "file": "box.obj", "angular_velocity_degrees": [1e300, 0, 0]})")
          .find("angular_velocity_degrees = "),
      std::string::npos);
  // Missing file.
  const std::string missing = read(R"({"kind": "mesh", "file": "nowhere.obj"})");
  EXPECT_EQ(missing.rfind("terrains[1].file = ", 0), 0u) << missing;
  EXPECT_NE(missing.find("nowhere.obj"), std::string::npos) << missing;
  EXPECT_NE(read(R"({"kind": "mesh"})").find("terrains[1].file"), std::string::npos);
  // Open: a box without its top.
  TriangleMesh open = box_mesh(Vec3(1, 1, 1));
  TriangleMesh lidless;
  lidless.vertices = open.vertices;
  for (const Triangle& t : open.triangles) {
    if (open.vertices[t[0]].y() > 0 && open.vertices[t[1]].y() > 0 && open.vertices[t[2]].y() > 0)
      continue;
    lidless.triangles.push_back(t);
  }
  ASSERT_EQ(lidless.num_triangles(), 10);
  dir.write("open.obj", lidless);
  const std::string holes = read(R"({"kind": "mesh", "file": "open.obj"})");
  EXPECT_EQ(holes.rfind("terrains[1].file = ", 0), 0u) << holes;
  EXPECT_NE(holes.find("a closed mesh"), std::string::npos) << holes;
  EXPECT_NE(holes.find("1 hole(s)"), std::string::npos) << holes;
  // Degenerate: a closed but flat mesh (two triangles back to back) encloses nothing.
  TriangleMesh flat;
  flat.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
  flat.triangles = {{0, 1, 2}, {0, 2, 1}};
  dir.write("flat.obj", flat);
  const std::string degenerate = read(R"({"kind": "mesh", "file": "flat.obj"})");
  EXPECT_EQ(degenerate.rfind("terrains[1].file = ", 0), 0u) << degenerate;
  EXPECT_NE(degenerate.find("enclosing a volume"), std::string::npos) << degenerate;
  // Zero area: every vertex at one point (the reader drops such triangles: no triangle left).
  std::ofstream(dir.file("point.obj")) << "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n";
  const std::string point = read(R"({"kind": "mesh", "file": "point.obj"})");
  EXPECT_EQ(point.rfind("terrains[1].file = ", 0), 0u) << point;
  // No triangle.
  std::ofstream(dir.file("empty.obj")) << "v 0 0 0\n";
  EXPECT_EQ(read(R"({"kind": "mesh", "file": "empty.obj"})").rfind("terrains[1].file = ", 0), 0u);
  // NaN in the file and in the scene.
  std::ofstream(dir.file("nan.obj")) << "v 0 0 0\nv 1 0 0\nv 0 nan 1\nv 0 1 0\n"
                                        "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  EXPECT_EQ(read(R"({"kind": "mesh", "file": "nan.obj"})").rfind("terrains[1].file = ", 0), 0u);
  dir.write("cube.obj", box_mesh(Vec3(1, 1, 1)));
  EXPECT_EQ(read(R"({"kind": "mesh", "file": "cube.obj", "scale": 0})"),
            "terrains[1].scale = 0 is invalid: a finite scale > 0");
  MeshObstacleSpec s;
  s.file = dir.file("cube.obj");
  s.pose.position = Vec3(0, std::numeric_limits<Real>::quiet_NaN(), 0);
  const std::string nan_position = error_of([&] { s.validate("terrains[2]."); });
  EXPECT_EQ(nan_position.rfind("terrains[2].position = ", 0), 0u) << nan_position;
  EXPECT_NE(error_of([&] { MeshObstacle{s}; }).find("obstacle.position"), std::string::npos);
}

}  // namespace
}  // namespace jelly
