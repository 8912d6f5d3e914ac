// The voxelized body kind: the lattice inside a mesh, its embedded render surface, the shape as
// a scene reads it, and its bad input.
#include <Eigen/Geometry>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/geometry/detail/box.hpp>
#include <jelly/geometry/detail/voxelized.hpp>
#include <jelly/io/scene.hpp>

#include "geometry_support.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using testing::input_error;
using testing::occupied;
using testing::TempDir;
using testing::write_text;

// A sphere with a part of a capsule sticking out of it: overlapping closed meshes, as the
// gummy bear is made.
TriangleMesh sphere_and_capsule() {
  TriangleMesh mesh = sphere_mesh(1, 24, 48);
  TriangleMesh capsule = capsule_mesh(0.35, 1.2, 8, 32);
  for (Vec3& v : capsule.vertices) v = Vec3(v.y() + 1.1, -v.x(), v.z());  // turned to x
  mesh.append(capsule);
  return mesh;
}

void expect_same_part(const BodyPart& a, const BodyPart& b) {
  ASSERT_EQ(a.num_particles(), b.num_particles());
  for (int i = 0; i < a.num_particles(); ++i) {
    EXPECT_LT((Vec3(particle(a.position, i)) - Vec3(particle(b.position, i))).norm(), 1e-12)
        << "particle " << i;
    EXPECT_NEAR(a.mass[i], b.mass[i], 1e-12 * a.mass[i]) << "particle " << i;
  }
  ASSERT_EQ(a.springs.size(), b.springs.size());
  for (int s = 0; s < a.springs.size(); ++s) {
    EXPECT_EQ(a.springs.a[s], b.springs.a[s]);
    EXPECT_EQ(a.springs.b[s], b.springs.b[s]);
    EXPECT_EQ(a.springs.type[s], b.springs.type[s]);
    EXPECT_NEAR(a.springs.rest_length[s], b.springs.rest_length[s], 1e-12);
    EXPECT_EQ(a.springs.ks[s], b.springs.ks[s]);
    EXPECT_EQ(a.springs.kd[s], b.springs.kd[s]);
  }
}

TEST(Voxelized, AnAxisAlignedBoxMeshGivesTheBoxLattice) {
  Material material;
  material.density = 1000;
  material.springs[1] = {900, 20};
  for (const Vec3& degrees : {Vec3(0, 0, 0), Vec3(10, -20, 35)}) {
    BoxShape box;
    box.n = {5, 4, 3};
    box.size = Vec3(1, 0.75, 0.5);
    box.pose.rotation_degrees = degrees;
    box.pose.position = Vec3(0.5, 2, -1);
    const BodyPart expected = box.build(material, "");
    const BodyPart part =
        build_voxelized(box_mesh(box.size), {}, 0.25, box.pose, material, "bodies[0].");
    SCOPED_TRACE(degrees.transpose());
    expect_same_part(part, expected);
  }
}

TEST(Voxelized, SphereParticleCountIsItsVolumeOverSpacingCubed) {
  const Real radius = 1;
  const TriangleMesh sphere = sphere_mesh(radius, 64, 128);
  for (Real h : {0.1, 0.13, 0.15}) {
    const Real expected = 4.0 / 3.0 * M_PI * std::pow(radius, 3) / std::pow(h, 3);
    const int count = occupied(voxelize(sphere, h));
    EXPECT_NEAR(count, expected, 0.05 * expected) << "h = " << h;
  }
}

TEST(Voxelized, AMeshWithASmallHoleStillFills) {
  const TriangleMesh sphere = sphere_mesh(1, 32, 64);
  TriangleMesh holed = sphere;
  holed.triangles.erase(holed.triangles.begin() + 900, holed.triangles.begin() + 902);  // a quad
  const MeshTopology topo = mesh_topology(holed);
  ASSERT_FALSE(topo.closed());
  ASSERT_EQ(topo.holes.size(), 1u);
  const Real h = 0.1;
  ASSERT_LT(topo.holes[0].diameter, VoxelizedShape::kMaxHoleSpacings * h);
  const LatticeGrid closed = voxelize(sphere, h), open = voxelize(holed, h);
  EXPECT_EQ(open.occupied, closed.occupied);

  // Through the scene's shape: the hole is accepted, a half sphere (one hole as wide as the
  // mesh) is not.
  TempDir dir;
  write_mesh(dir.file("holed.obj"), holed);
  VoxelizedShape shape;
  shape.file = dir.file("holed.obj");
  shape.spacing = h;
  EXPECT_NO_THROW(shape.validate("bodies[0]."));
  EXPECT_EQ(shape.build(Material{}, "").num_particles(), occupied(closed));
  TriangleMesh half = sphere;
  half.triangles.resize(half.triangles.size() / 2);
  write_mesh(dir.file("half.obj"), half);
  shape.file = dir.file("half.obj");
  const std::string message = input_error([&] { shape.validate("bodies[0]."); });
  EXPECT_THAT(message, HasSubstr("bodies[0].file = \"" + shape.file + "\" is invalid"));
  EXPECT_THAT(message, HasSubstr("hole"));
}

TEST(Voxelized, OverlappingPartsFillTheirUnion) {
  const Real h = 0.1;
  const int both = occupied(voxelize(sphere_and_capsule(), h));
  const int sphere = occupied(voxelize(sphere_mesh(1, 24, 48), h));
  EXPECT_GT(both, sphere + 30);  // the capsule's part outside the sphere
  // The union's volume: the sphere plus the capsule beyond it (x > ~0.94), about 4.19 + 0.47.
  EXPECT_NEAR(both * h * h * h, 4.66, 0.25);
}

// The mesh's vertices, placed by the pose.
std::vector<Vec3> placed(const TriangleMesh& mesh, const Pose& pose) {
  std::vector<Vec3> out;
  for (const Vec3& v : mesh.vertices) out.push_back(pose.apply(v));
  return out;
}

TEST(Voxelized, EmbeddedSurfaceReproducesTheMeshAndFollowsRigidMotion) {
  Pose pose;
  pose.scale = 1.3;
  pose.rotation_degrees = Vec3(10, 20, 30);
  pose.position = Vec3(1, 2, 3);
  for (Real h : {0.12, 0.3}) {
    SCOPED_TRACE(h);
    const TriangleMesh mesh = sphere_and_capsule();
    const BodyPart part = build_voxelized(mesh, {}, h, pose, Material{}, "");
    const Surface& s = part.surface;
    ASSERT_EQ(s.num_vertices(), mesh.num_vertices());
    ASSERT_EQ(s.triangles, mesh.triangles);  // outwards already
    // Vertices outside every fully occupied cell are there, and use extrapolated weights.
    int extrapolated = 0;
    for (Real w : s.weights) extrapolated += (w < 0 || w > 1);
    EXPECT_GT(extrapolated, 0);

    const std::vector<Vec3> rest = placed(mesh, pose);
    for (int v = 0; v < s.num_vertices(); ++v) {
      Real sum = 0;
      for (int k = s.offsets[v]; k < s.offsets[v + 1]; ++k) sum += s.weights[k];
      ASSERT_NEAR(sum, 1, 1e-12);
      ASSERT_LT((s.vertex(part.position, v) - rest[v]).norm(), 1e-12) << "vertex " << v;
    }
    // A rigid motion of the lattice moves the surface the same way.
    const Eigen::Matrix3d q =
        Eigen::AngleAxisd(2.1, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
    const Vec3 shift(-3, 0.25, 7);
    VecX moved = part.position;
    for (int i = 0; i < part.num_particles(); ++i) {
      particle(moved, i) = q * Vec3(particle(part.position, i)) + shift;
    }
    for (int v = 0; v < s.num_vertices(); ++v) {
      ASSERT_LT((s.vertex(moved, v) - (q * rest[v] + shift)).norm(), 1e-12) << "vertex " << v;
    }
  }
}

TEST(Voxelized, VertexGroupsBecomeTheParticlesTheirVerticesFollow) {
  TempDir dir;
  // A box of quads with its top face as group "top".
  const std::string text =
      "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
      "g sides\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 1 5 8\nf 2 3 7 6\n"
      "g top\nf 3 4 8 7\n";
  VoxelizedShape shape;
  shape.file = write_text(dir.file("box.obj"), text);
  shape.spacing = 0.5;
  const BodyPart part = shape.build(Material{}, "");
  EXPECT_EQ(part.num_particles(), 125);
  ASSERT_EQ(part.groups.size(), 2u);
  const ParticleGroup& top = part.groups[1];
  EXPECT_EQ(top.name, "top");
  ASSERT_EQ(top.particles.size(), 4u);  // the 4 corners at y = 1
  for (int p : top.particles) EXPECT_EQ(part.position[3 * p + 1], 1.0);
}

TEST(Voxelized, BadSpacingsAreInputErrorsNamingTheField) {
  const TriangleMesh sphere = sphere_mesh(1, 16, 32);
  const auto error = [&](Real h) {
    return input_error([&] { build_voxelized(sphere, {}, h, Pose{}, Material{}, "bodies[2]."); });
  };
  EXPECT_THAT(error(0), HasSubstr("bodies[2].spacing = 0 is invalid"));
  EXPECT_THAT(error(-1), HasSubstr("bodies[2].spacing"));
  EXPECT_THAT(error(std::nan("")), HasSubstr("bodies[2].spacing = nan"));
  EXPECT_THAT(error(1.5), HasSubstr("at least 8 lattice points"));
  EXPECT_THAT(error(0.9), HasSubstr("bodies[2].spacing = 0.9"));
}

// A scene in a folder of its own naming its mesh by a relative path.
TEST(VoxelizedScene, MeshFileIsRelativeToTheSceneFolder) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "scenes" / "meshes");
  write_mesh((dir.path() / "scenes" / "meshes" / "ball.stl").string(), sphere_mesh(0.5, 16, 32));
  const std::string scene_path = write_text((dir.path() / "scenes" / "ball.json").string(), R"({
    "bodies": [{"kind": "voxelized", "name": "ball", "file": "meshes/ball.stl", "spacing": 0.1,
                "position": [0, 2, 0]}],
    "integrator": {"name": "rk4"}, "duration": 1})");
  const Scene scene = load_scene(scene_path);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const auto& shape = scene.bodies[0].shape.as<VoxelizedShape>();
  EXPECT_EQ(shape.file, (dir.path() / "scenes" / "meshes" / "ball.stl").string());
  EXPECT_GT(shape.estimated_particles(), 400);
  const Model model = make_model(scene);
  EXPECT_GT(model.num_particles(), 400);
  EXPECT_LE(model.num_particles(), shape.estimated_particles());
  EXPECT_EQ(model.bodies[0].kind, "voxelized");
  // Written with the absolute path: it reads back from anywhere.
  const std::string text = scene_to_json(scene);
  EXPECT_EQ(scene_to_json(parse_scene(text)), text);
}

TEST(VoxelizedScene, BadInputNamesTheField) {
  TempDir dir;
  write_mesh(dir.file("ball.obj"), sphere_mesh(0.5, 16, 32));
  const auto error = [&](const std::string& body, const std::string& extra = "") {
    const std::string path = write_text(dir.file("s.json"), R"({"bodies": [)" + body +
                                                                R"(], "integrator": {"name": "rk4"},
                                                               "duration": 1)" +
                                                                extra + "}");
    return input_error([&] { make_model(load_scene(path)); });
  };
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "nope.obj", "spacing": 0.1})"),
              HasSubstr("bodies[0].file = \"" + dir.file("nope.obj") + "\" is invalid"));
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "", "spacing": 0.1})"),
              HasSubstr("bodies[0].file"));
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "ball.obj"})"),
              HasSubstr("bodies[0].spacing is missing"));
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "ball.obj", "spacing": 2})"),
              HasSubstr("bodies[0].spacing = 2 is invalid"));
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "ball.obj", "spacing": 0.1, "scale": 0})"),
              HasSubstr("bodies[0].scale = 0 is invalid"));
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "ball.obj", "spacing": 0.01})",
                    R"(, "max_particles": 100000)"),
              HasSubstr("max_particles = 100000"));
  EXPECT_THAT(error(R"({"kind": "voxelized", "file": "ball.obj", "spacing": 0.1, "n": 3})"),
              HasSubstr("bodies[0].n"));
}

}  // namespace
}  // namespace jelly
