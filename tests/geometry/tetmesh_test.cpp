// The tetmesh body kind: springs = unique edges, lumped masses, the boundary surface; the Gmsh
// and TetGen readers, tetrahedralize, and their bad input.
#include <Eigen/Geometry>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/geometry/detail/tetrahedralize.hpp>
#include <jelly/io/scene.hpp>

#include "geometry_support.hpp"

namespace jelly {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using testing::input_error;
using testing::TempDir;
using testing::write_text;

// The unit cube's corners, corner c at (c & 1, c >> 1 & 1, c >> 2 & 1).
std::vector<Vec3> cube_corners() {
  std::vector<Vec3> v;
  for (int c = 0; c < 8; ++c) v.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  return v;
}

// Four corner tets and the central one: 12 cube edges + 6 face diagonals = 18 edges.
TetMesh cube_in_5_tets() {
  return {
      cube_corners(), {{0, 1, 2, 4}, {3, 2, 1, 7}, {5, 1, 4, 7}, {6, 4, 2, 7}, {1, 2, 4, 7}}, {}};
}

// Six tets around the diagonal 0-7 (Kuhn): 12 + 6 + 1 = 19 edges.
TetMesh cube_in_6_tets() {
  TetMesh m{cube_corners(), {}, {}};
  const int axes[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
  for (const auto& a : axes) m.tets.push_back({0, a[0], a[0] + a[1], 7});
  return m;
}

Real volume_of(const TetMesh& m) {
  Real v = 0;
  for (const Tet& t : m.tets) {
    const Vec3& a = m.vertices[t[0]];
    v += std::abs((m.vertices[t[1]] - a).dot((m.vertices[t[2]] - a).cross(m.vertices[t[3]] - a)));
  }
  return v / 6;
}

// The unique edges counted with a set, independently of tet_edges.
std::size_t unique_edges(const TetMesh& m) {
  std::set<std::pair<int, int>> edges;
  for (const Tet& t : m.tets)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) edges.insert(std::minmax(t[i], t[j]));
  return edges.size();
}

void expect_outward(const Surface& s, const VecX& x, const Vec3& inside) {
  for (const Triangle& t : s.triangles) {
    const Vec3 a = s.vertex(x, t[0]), b = s.vertex(x, t[1]), c = s.vertex(x, t[2]);
    EXPECT_GT((b - a).cross(c - a).dot((a + b + c) / 3 - inside), 0);
  }
}

TEST(Tetmesh, CubeIn5And6TetsSpringsAreTheUniqueEdges) {
  Material material;
  material.density = 250;
  material.springs[0] = {700, 3};
  Pose pose;
  pose.scale = 2;
  pose.position = Vec3(1, 2, 3);
  pose.rotation_degrees = Vec3(0, 0, 30);
  for (const auto& [mesh, edges] :
       {std::pair{cube_in_5_tets(), 18}, std::pair{cube_in_6_tets(), 19}}) {
    SCOPED_TRACE(mesh.num_tets());
    EXPECT_NEAR(volume_of(mesh), 1, 1e-15);
    const BodyPart part = build_tetmesh(mesh, pose, material, "");
    EXPECT_EQ(part.num_particles(), 8);
    ASSERT_EQ(part.springs.size(), edges);
    ASSERT_EQ(tet_edges(mesh.tets).size(), static_cast<std::size_t>(edges));
    std::set<std::pair<int, int>> seen;
    for (int s = 0; s < part.springs.size(); ++s) {
      EXPECT_EQ(part.springs.type[s], SpringType::kStructural);
      EXPECT_EQ(part.springs.ks[s], 700);
      EXPECT_TRUE(seen.insert({part.springs.a[s], part.springs.b[s]}).second);
      const Real length =
          pose.scale * (mesh.vertices[part.springs.a[s]] - mesh.vertices[part.springs.b[s]]).norm();
      EXPECT_NEAR(part.springs.rest_length[s], length, 1e-12);
    }
    // Masses: density x volume (scale^3), lumped a quarter per corner.
    EXPECT_NEAR(part.mass.sum(), 250 * 8, 1e-9);
    // The boundary: the cube's 6 faces, 2 triangles each, outwards.
    EXPECT_EQ(part.surface.num_triangles(), 12);
    EXPECT_EQ(part.surface.num_vertices(), 8);
    expect_outward(part.surface, part.position, pose.apply(Vec3(0.5, 0.5, 0.5)));
  }
  // The central tet of the 5-split holds a third of the volume: its corners weigh more.
  const BodyPart five = build_tetmesh(cube_in_5_tets(), Pose{}, material, "");
  EXPECT_NEAR(five.mass[0], 250.0 / 6 / 4, 1e-12);                    // one corner tet
  EXPECT_NEAR(five.mass[7], 250.0 * (3.0 / 6 + 1.0 / 3) / 4, 1e-12);  // three corner + central
  // Without density: particle_mass each.
  EXPECT_EQ(build_tetmesh(cube_in_5_tets(), Pose{}, Material{}, "").mass, VecX::Ones(8));
}

TEST(Tetmesh, GmshFillsASphereAndTheMeshIsConsistent) {
  const TriangleMesh sphere = sphere_mesh(1, 10, 20);
  const TetMesh mesh = tetrahedralize(sphere, 0, "IN");
  ASSERT_GT(mesh.num_tets(), 100);
  // The surface is kept: its vertices come first... at least all of them are there, and the
  // tets fill exactly the polyhedron it bounds.
  EXPECT_GE(mesh.num_vertices(), sphere.num_vertices());
  Real enclosed = 0;
  for (const Triangle& t : sphere.triangles) {
    enclosed += sphere.vertices[t[0]].dot(sphere.vertices[t[1]].cross(sphere.vertices[t[2]]));
  }
  EXPECT_NEAR(volume_of(mesh), enclosed / 6, 1e-9);
  const std::vector<Triangle> boundary = tet_boundary(mesh.tets, mesh.vertices);
  EXPECT_EQ(boundary.size(), sphere.triangles.size());
  // Springs = unique edges; Euler's formula for a ball: V - E + F - T = 1.
  const BodyPart part = build_tetmesh(mesh, Pose{}, Material{}, "");
  EXPECT_EQ(static_cast<std::size_t>(part.springs.size()), unique_edges(mesh));
  const long faces = (4L * mesh.num_tets() + static_cast<long>(boundary.size())) / 2;
  EXPECT_EQ(mesh.num_vertices() - part.springs.size() + faces - mesh.num_tets(), 1);
  expect_outward(part.surface, part.position, Vec3::Zero());
  // The physical groups Gmsh was given.
  ASSERT_EQ(mesh.groups.size(), 2u);
  EXPECT_EQ(mesh.groups[0].name, "boundary");
  EXPECT_EQ(mesh.groups[0].vertices.size(), sphere.vertices.size());
  EXPECT_EQ(mesh.groups[1].name, "volume");
  EXPECT_EQ(mesh.groups[1].vertices.size(), static_cast<std::size_t>(mesh.num_vertices()));
  // A remeshed surface at a given size: smaller elements, more tets.
  const TetMesh fine = tetrahedralize(sphere, 0.25, "--size");
  EXPECT_GT(fine.num_tets(), mesh.num_tets());
  EXPECT_NEAR(volume_of(fine), enclosed / 6, 0.05 * enclosed / 6);
}

// A size that would make Gmsh fill the surface with billions of tetrahedra is refused before
// Gmsh starts, naming the size field, the estimate and the smallest size allowed.
TEST(Tetmesh, ATinyElementSizeIsRefusedBeforeGmshStarts) {
  const TriangleMesh sphere = sphere_mesh(1, 8, 16);
  EXPECT_THAT(input_error([&] { tetrahedralize(sphere, 1e-4, "IN", "ball", "--size"); }),
              AllOf(HasSubstr("--size = 0.0001"), HasSubstr("at most 1e+07 tetrahedra"),
                    HasSubstr("the smallest size allowed is about 0.01")));
  EXPECT_NO_THROW(tetrahedralize(sphere, 0.5, "IN", "ball", "--size"));
}

// The memory estimate counts the springs a tetmesh body will have: its unique edges, not an
// upper bound of 6 per tet (five times too many on a regular mesh; issue 44).
TEST(Tetmesh, EstimatedSpringsAreTheMeshEdges) {
  TempDir dir;
  write_msh(dir.file("cube.msh"), cube_in_6_tets());
  TetmeshShape shape;
  shape.file = dir.file("cube.msh");
  const BodyPart part = shape.build(Material{}, "bodies[0].");
  EXPECT_EQ(shape.estimated_springs(), static_cast<long>(part.springs.size()));
  EXPECT_EQ(shape.estimated_springs(), 19);
  EXPECT_EQ(shape.estimated_particles(), 8);
}

TEST(Tetmesh, MshAndTetgenFilesReadBack) {
  TempDir dir;
  const TetMesh cube = cube_in_6_tets();
  write_msh(dir.file("cube.msh"), cube);
  const TetMesh msh = read_tet_mesh(dir.file("cube.msh"), "file");
  EXPECT_EQ(msh.num_vertices(), 8);
  EXPECT_EQ(msh.num_tets(), 6);
  EXPECT_NEAR(volume_of(msh), 1, 1e-12);
  EXPECT_EQ(unique_edges(msh), 19u);
  ASSERT_EQ(msh.groups.size(), 2u);
  EXPECT_EQ(msh.groups[0].name, "boundary");
  EXPECT_EQ(msh.groups[1].name, "volume");
  // A Gmsh-made mesh through the file.
  const TetMesh ball = tetrahedralize(sphere_mesh(1, 8, 16), 0, "IN");
  write_msh(dir.file("ball.msh"), ball);
  const TetMesh again = read_tet_mesh(dir.file("ball.msh"), "file");
  EXPECT_EQ(again.num_tets(), ball.num_tets());
  EXPECT_EQ(unique_edges(again), unique_edges(ball));
  EXPECT_NEAR(volume_of(again), volume_of(ball), 1e-12);

  // TetGen, numbered from 1, with a region attribute, markers and an unused vertex.
  write_text(dir.file("cube.node"),
             "# the unit cube\n9 3 0 1\n"
             "1 0 0 0 1\n2 1 0 0 0\n3 0 1 0 0\n4 1 1 0 0\n"
             "5 0 0 1 0\n6 1 0 1 0\n7 0 1 1 0\n8 1 1 1 2\n9 5 5 5 0\n");
  write_text(dir.file("cube.ele"),
             "5 4 1\n1 1 2 3 5 10\n2 4 3 2 8 10\n3 6 2 5 8 10\n4 7 5 3 8 10\n5 2 3 5 8 20\n");
  for (const char* name : {"cube.node", "cube.ele"}) {
    const TetMesh tg = read_tet_mesh(dir.file(name), "file");
    EXPECT_EQ(tg.num_vertices(), 8);  // vertex 9 belongs to no tet
    EXPECT_EQ(tg.num_tets(), 5);
    EXPECT_EQ(unique_edges(tg), 18u);
    EXPECT_NEAR(volume_of(tg), 1, 1e-15);
    std::map<std::string, std::size_t> groups;
    for (const VertexGroup& g : tg.groups) groups[g.name] = g.vertices.size();
    EXPECT_EQ(groups, (std::map<std::string, std::size_t>{
                          {"region_10", 8}, {"region_20", 4}, {"marker_1", 1}, {"marker_2", 1}}));
  }
}

TEST(Tetmesh, SceneBodyWithRelativeFileAndGroupPins) {
  TempDir dir;
  write_msh(dir.file("cube.msh"), cube_in_5_tets());
  const std::string path = write_text(dir.file("scene.json"), R"({
    "bodies": [{"kind": "tetmesh", "name": "block", "file": "cube.msh", "scale": 0.5,
                "density": 1000, "pins": [{"group": "boundary"}]}],
    "integrator": {"name": "rk4"}, "duration": 1})");
  const Scene scene = load_scene(path);
  EXPECT_EQ(scene.bodies[0].shape->estimated_particles(), 8);
  const Model model = make_model(scene);
  EXPECT_EQ(model.num_particles(), 8);
  EXPECT_EQ(model.springs.size(), 18);
  EXPECT_NEAR(model.mass.sum(), 1000 * 0.125, 1e-9);
  EXPECT_EQ(model.pins.size(), 8);
  EXPECT_EQ(scene_to_json(parse_scene(scene_to_json(scene))), scene_to_json(scene));
}

TEST(Tetmesh, BadInputNamesFieldAndValue) {
  TempDir dir;
  const std::string field = "bodies[0].file";
  const auto error = [&](const std::string& path) {
    return input_error([&] { read_tet_mesh(path, field); });
  };
  const std::string missing = dir.file("missing.msh");
  EXPECT_THAT(error(missing), HasSubstr(field + " = \"" + missing + "\" is invalid: an existing"));
  EXPECT_THAT(error(dir.file("x.vtk")), HasSubstr(".msh (Gmsh) or .node/.ele (TetGen)"));
  EXPECT_THAT(error(write_text(dir.file("junk.msh"), "junk\n")),
              HasSubstr("a Gmsh mesh (MSH 2.2 or 4.1): line 1"));
  EXPECT_THAT(error(write_text(dir.file("empty.msh"), "")), HasSubstr(field));
  // A mesh of one hexahedron.
  const std::string hex =
      write_text(dir.file("hex.msh"),
                 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n"
                 "$EndEntities\n$Nodes\n1 8 1 8\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n"
                 "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n$EndNodes\n"
                 "$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n$EndElements\n");
  EXPECT_THAT(error(hex), HasSubstr("4-node tetrahedra"));
  // Only triangles: no tetrahedron.
  EXPECT_THAT(error(write_text(dir.file("surface.msh"),
                               "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n"
                               "1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n$Elements\n1 1 1 1\n"
                               "2 1 2 1\n1 1 2 3\n$EndElements\n")),
              HasSubstr("at least one tetrahedron"));
  // TetGen: a missing .ele, an index out of range, a NaN, a flat tet.
  write_text(dir.file("a.node"), "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
  EXPECT_THAT(error(dir.file("a.node")), HasSubstr("not found: " + dir.file("a.ele")));
  write_text(dir.file("a.ele"), "1 4 0\n0 0 1 2 7\n");
  EXPECT_THAT(error(dir.file("a.ele")), HasSubstr("vertex index 7 out of range"));
  write_text(dir.file("b.node"), "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 nan\n");
  write_text(dir.file("b.ele"), "1 4 0\n0 0 1 2 3\n");
  EXPECT_THAT(error(dir.file("b.ele")), HasSubstr(field));
  write_text(dir.file("c.node"), "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 1 1 0\n");
  write_text(dir.file("c.ele"), "1 4 0\n0 0 1 2 3\n");
  EXPECT_THAT(error(dir.file("c.ele")), HasSubstr("tet 0 is flat"));
  write_text(dir.file("d.node"), "2 3 0 0\n0 0 0 0\n");
  write_text(dir.file("d.ele"), "1 4 0\n0 0 1 2 3\n");
  EXPECT_THAT(error(dir.file("d.node")), HasSubstr("end of the file"));

  // tetrahedralize: an open surface, a bad size.
  TriangleMesh open = sphere_mesh(1, 8, 16);
  open.triangles.pop_back();
  EXPECT_THAT(input_error([&] { tetrahedralize(open, 0, "IN", "ball.stl"); }),
              HasSubstr("IN = \"ball.stl\" is invalid: a closed mesh"));
  EXPECT_THAT(input_error([&] { tetrahedralize(sphere_mesh(1), -1, "IN", "s", "--size"); }),
              HasSubstr("--size = -1"));
}

}  // namespace
}  // namespace jelly
