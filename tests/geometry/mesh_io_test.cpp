// Reading meshes: formats, welding, vertex groups, topology, and each kind of bad file.
#include <Eigen/Geometry>
#include <cstdint>
#include <fstream>
#include <iterator>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/geometry/detail/mesh_io.hpp>

#include "geometry_support.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using testing::input_error;
using testing::TempDir;
using testing::write_text;

// A tetrahedron, outward, as OBJ text with two groups.
constexpr const char* kTetrahedronObj =
    "# a tetrahedron\n"
    "o body\n"
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 3 2\nf 1 2 4\n"
    "g foot\nf 1 4 3\n"
    "g head\nf 2 3 4\n";

TEST(MeshIo, ReadsEachFormatAndWeldsRepeatedVertices) {
  TempDir dir;
  const TriangleMesh box = box_mesh(Vec3(1, 2, 3));
  for (const char* name : {"box.obj", "box.stl", "box.ply", "BOX.STL"}) {
    write_mesh(dir.file(name), box);
    const MeshFile read = read_mesh(dir.file(name), "file");
    EXPECT_EQ(read.mesh.num_vertices(), 8) << name;  // STL repeats them per triangle
    EXPECT_EQ(read.mesh.num_triangles(), 12) << name;
    EXPECT_TRUE(read.mesh.bounds().isApprox(box.bounds())) << name;
    const MeshTopology topo = mesh_topology(read.mesh);
    EXPECT_TRUE(topo.closed() && topo.manifold()) << name;
    EXPECT_EQ(topo.edges, 18) << name;
  }
}

TEST(MeshIo, ObjectAndGroupNamesAreVertexGroups) {
  TempDir dir;
  const MeshFile read = read_mesh(write_text(dir.file("t.obj"), kTetrahedronObj), "file");
  ASSERT_EQ(read.mesh.num_triangles(), 4);
  ASSERT_EQ(read.groups.size(), 3u);
  std::map<std::string, std::vector<Vec3>> points;
  for (const VertexGroup& g : read.groups) {
    for (int v : g.vertices) points[g.name].push_back(read.mesh.vertices[v]);
  }
  ASSERT_EQ(points["foot"].size(), 3u);  // 1 4 3: (0,0,0), (0,0,1), (0,1,0)
  for (const Vec3& p : points["foot"]) EXPECT_EQ(p.x(), 0);
  ASSERT_EQ(points["head"].size(), 3u);
  EXPECT_EQ(points["body"].size(), 4u);
}

TEST(MeshIo, PolygonsAreSplitAndDegenerateTrianglesDropped) {
  TempDir dir;
  // A cube of quads, one extra triangle with a repeated vertex.
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\nf 1 1 2\n";
  const MeshFile read = read_mesh(write_text(dir.file("q.obj"), text), "file");
  EXPECT_EQ(read.mesh.num_triangles(), 12);
  EXPECT_TRUE(mesh_topology(read.mesh).closed());
}

TEST(MeshIo, HolesAreFoundAsLoops) {
  TriangleMesh sphere = sphere_mesh(1, 8, 16);
  sphere.triangles.erase(sphere.triangles.begin() + 100);
  sphere.triangles.erase(sphere.triangles.begin() + 40);  // two rings apart: two holes
  const MeshTopology topo = mesh_topology(sphere);
  EXPECT_FALSE(topo.closed());
  EXPECT_TRUE(topo.manifold());
  EXPECT_EQ(topo.boundary_edges, 6);
  ASSERT_EQ(topo.holes.size(), 2u);
  EXPECT_EQ(topo.holes[0].vertices.size(), 3u);
  EXPECT_GT(topo.holes[0].diameter, 0);
  EXPECT_LT(topo.holes[0].diameter, 1);
  EXPECT_NO_THROW(require_small_holes(topo, 1, "file", "s.obj", "filled"));
  const std::string message =
      input_error([&] { require_small_holes(topo, 0.01, "bodies[0].file", "s.obj", "filled"); });
  EXPECT_THAT(message, HasSubstr("bodies[0].file = \"s.obj\" is invalid"));
  EXPECT_THAT(message, HasSubstr("2 hole(s)"));
}

TEST(MeshIo, BadFilesAreInputErrorsNamingFieldAndFile) {
  TempDir dir;
  const std::string field = "bodies[1].file";
  const auto error = [&](const std::string& path) {
    return input_error([&] { read_mesh(path, field); });
  };
  const std::string missing = dir.file("missing.obj");
  EXPECT_THAT(error(missing), HasSubstr(field + " = \"" + missing + "\" is invalid: an existing"));
  EXPECT_THAT(error(dir.path().string() + "/folder.obj"), HasSubstr("not found"));
  std::filesystem::create_directory(dir.file("dir.obj"));
  EXPECT_THAT(error(dir.file("dir.obj")), HasSubstr("a regular file"));
  EXPECT_THAT(error(write_text(dir.file("m.3ds"), "x")), HasSubstr(".obj, .stl or .ply"));
  EXPECT_THAT(error(write_text(dir.file("empty.obj"), "")), HasSubstr(field + " = \""));
  EXPECT_THAT(error(write_text(dir.file("nofaces.obj"), "# nothing\nv 0 0 0\nv 1 0 0\n")),
              HasSubstr(field));
  EXPECT_THAT(error(write_text(dir.file("empty.stl"), "solid e\nendsolid e\n")), HasSubstr(field));
  EXPECT_THAT(error(write_text(dir.file("garbage.ply"), "not a ply file\n")), HasSubstr(field));
  const std::string nan = write_text(dir.file("nan.obj"),
                                     "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  EXPECT_THAT(error(nan), HasSubstr("finite coordinates"));
  // Three triangles on the edge 1-2.
  const std::string fin = write_text(dir.file("fin.obj"),
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 -1 0\n"
                                     "f 1 2 3\nf 2 1 4\nf 1 2 5\n");
  EXPECT_THAT(error(fin), HasSubstr("manifold"));
  // One triangle of a tetrahedron turned inside out.
  const std::string flipped = write_text(dir.file("flipped.obj"),
                                         "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                         "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 4 3\n");
  EXPECT_THAT(error(flipped), HasSubstr("consistently oriented"));
}

// A tetrahedron as ASCII PLY whose last face is `last_face`.
std::string tetrahedron_ply(const std::string& last_face, const std::string& vertices = "4") {
  return "ply\nformat ascii 1.0\nelement vertex " + vertices +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face 4\n"
         "property list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n" +
         last_face + "\n";
}

TEST(MeshIo, FaceIndicesOutsideTheVerticesAreRefusedNotFollowed) {
  TempDir dir;
  const std::string field = "terrains[0].file";
  const auto error = [&](const std::string& name, const std::string& text) {
    return input_error([&] { read_mesh(write_text(dir.file(name), text), field); });
  };
  EXPECT_EQ(read_mesh(write_text(dir.file("ok.ply"), tetrahedron_ply("3 1 2 3")), field)
                .mesh.num_triangles(),
            4);
  for (const char* face : {"3 1 2 -5", "3 1 2 4", "3 1 2 2147483647", "3 -1 2 3"}) {
    SCOPED_TRACE(face);
    const std::string message = error("bad.ply", tetrahedron_ply(face));
    EXPECT_THAT(message, HasSubstr(field + " = \"" + dir.file("bad.ply") + "\" is invalid"));
  }
  EXPECT_THAT(error("past.ply", tetrahedron_ply("3 1 2 9")), HasSubstr("out of range"));
  EXPECT_THAT(error("past.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 9\n"), HasSubstr(field));
  // A vertex count far beyond the file's content (assimp allocated room for all of them before
  // reading one).
  EXPECT_THAT(error("count.ply", tetrahedron_ply("3 1 2 3", "2000000000")),
              HasSubstr("counts fit in it (its header says element vertex 2000000000"));
  EXPECT_THAT(error("negative.ply", tetrahedron_ply("3 1 2 3", "-4")),
              HasSubstr("element vertex -4"));
  // A face's list length far beyond the file (assimp allocated room for it before reading it),
  // ASCII and binary.
  const std::string header =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uint int vertex_indices\nend_header\n";
  EXPECT_THAT(error("list.ply", "ply\nformat ascii 1.0\n" + header +
                                    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n4000000000 0 1 2\n"),
              HasSubstr("element face 0 has a list of 4000000000 items"));
  std::string binary = "ply\nformat binary_little_endian 1.0\n" + header;
  const float xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  binary.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  const std::uint32_t length = 4000000000u;
  const std::int32_t items[3] = {0, 1, 2};
  binary.append(reinterpret_cast<const char*>(&length), 4);
  binary.append(reinterpret_cast<const char*>(items), sizeof items);
  EXPECT_THAT(error("list_binary.ply", binary),
              HasSubstr("element face 0 has a list of 4000000000 items"));
}

// A PLY file goes to assimp only when jelly's own walk of its header and body reached the end:
// assimp read past its buffer (SIGSEGV) on a binary file whose "end_header" line was damaged
// (issue 44, jelly_mesh_fuzzer; the input is in tests/fuzz/corpus/mesh).
TEST(MeshIo, PlyFilesTheWalkCannotFollowAreRefusedBeforeAssimp) {
  TempDir dir;
  const std::string field = "bodies[0].file";
  const auto error = [&](const std::string& name, const std::string& text) {
    return input_error([&] { read_mesh(write_text(dir.file(name), text), field); });
  };
  const std::string header =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\n"
      "property list uchar int vertex_indices\n";
  std::string body;
  const float xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  body.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    body += '\3';
    body.append(reinterpret_cast<const char*>(f), sizeof f);
  }
  const std::string binary = "ply\nformat binary_little_endian 1.0\n" + header;
  EXPECT_EQ(read_mesh(write_text(dir.file("ok.ply"), binary + "end_header\n" + body), field)
                .mesh.num_triangles(),
            4);
  EXPECT_THAT(error("damaged.ply", binary + "end_h~ader\n" + body),
              HasSubstr("a well-formed PLY file (no line \"end_header\" ends its header)"));
  EXPECT_THAT(error("short.ply", binary + "end_header\n" + body.substr(0, body.size() - 5)),
              HasSubstr("element face 3 has a list of 3 items, more than the 7 bytes left"));
  EXPECT_THAT(error("short_vertices.ply", binary + "end_header\n" + body.substr(0, 20)),
              HasSubstr("it ends inside element vertex 1 of 4"));
  EXPECT_THAT(error("line.ply", "ply\nformat ascii 1.0\nfoo\n" + header + "end_header\n"),
              HasSubstr("header line 3 starts with 'foo'"));
  EXPECT_THAT(error("version.ply", "ply\nformat ascii 2.0\n" + header + "end_header\n"),
              HasSubstr("format version '2.0', not 1.0"));
  EXPECT_THAT(error("format.ply", "ply\nformat text 1.0\n" + header + "end_header\n"),
              HasSubstr("format 'text'"));
  EXPECT_THAT(error("fraction.ply", tetrahedron_ply("2.5 1 2 3")),
              HasSubstr("a list length '2.5', not a whole number"));
  EXPECT_THAT(error("ascii_short.ply", tetrahedron_ply("3 1 2")),
              HasSubstr("it ends inside element face 3 of 4"));
  // Faces of no vertex: assimp's triangulation aborted (an assertion) on them.
  EXPECT_THAT(error("empty_face.ply", tetrahedron_ply("0")),
              HasSubstr("element face 3 has a list of 0 vertices; a face has at least 3"));
  EXPECT_THAT(error("edge_face.ply", tetrahedron_ply("2 1 2")),
              HasSubstr("element face 3 has a list of 2 vertices"));
  // An ASCII element is one line, as assimp reads it (a list read across lines by the walk and
  // along one by assimp made assimp allocate what a number said: jelly_mesh_fuzzer).
  EXPECT_THAT(error("two_lines.ply", tetrahedron_ply("3 1\n2 3")),
              HasSubstr("it ends inside element face 3 of 4"));
  EXPECT_THAT(error("extra.ply", tetrahedron_ply("3 1 2 3 4")),
              HasSubstr("element face 3 has more on its line than its properties"));
}

// Text formats hold no control characters: an OBJ file with a NUL byte sent assimp's OBJ reader
// past its buffer (issue 44, jelly_mesh_fuzzer; the input is in tests/fuzz/corpus/mesh). A binary
// STL file, which may begin with "solid" as well, is still read.
TEST(MeshIo, TextMeshFilesWithControlCharactersAreRefusedBeforeAssimp) {
  TempDir dir;
  const std::string field = "terrains[0].file";
  const auto error = [&](const std::string& name, const std::string& text) {
    return input_error([&] { read_mesh(write_text(dir.file(name), text), field); });
  };
  EXPECT_THAT(error("nul.obj", std::string("\0p 2v\x12", 6) + "0y0forma 0 m"),
              HasSubstr("a text OBJ file (byte 0 is 0x00, a control character"));
  const std::string tetrahedron =
      "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 0 0 1\r\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  EXPECT_EQ(read_mesh(write_text(dir.file("ok.obj"), tetrahedron), field).mesh.num_triangles(), 4);
  // Its last line without a line break (assimp's OBJ reader parsed its last number past the end
  // of its buffer then: jelly hands the file over ending in one).
  EXPECT_EQ(read_mesh(write_text(dir.file("no_newline.obj"),
                                 tetrahedron.substr(0, tetrahedron.size() - 1)),
                      field)
                .mesh.num_triangles(),
            4);
  EXPECT_THAT(error("bell.obj", "v 0 0 0\x07\n" + tetrahedron), HasSubstr("byte 7 is 0x07"));
  EXPECT_THAT(error("ascii.stl", std::string("solid t\n\0", 9)), HasSubstr("a text STL file"));
  // An ASCII PLY file: a NUL byte in a vertex line made assimp abort on an assertion.
  EXPECT_THAT(error("nul.ply", std::string("ply\nformat ascii 1.0\nelement vertex 1\n"
                                           "property float x\nproperty float y\n"
                                           "property float z\nend_header\n1 \0 0 0\n",
                                           108)),
              HasSubstr("a text PLY file (byte 102 is 0x00"));
  // Binary, named "solid ...": 84 + 50 n bytes.
  const TriangleMesh box = box_mesh(Vec3::Ones());
  write_mesh(dir.file("box.stl"), box);
  std::ifstream in(dir.file("box.stl"), std::ios::binary);
  std::string binary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(binary.size(), 84u + 50u * static_cast<size_t>(box.num_triangles()));
  binary.replace(0, 6, "solid ");
  EXPECT_EQ(read_mesh(write_text(dir.file("solid.stl"), binary), field).mesh.num_triangles(),
            box.num_triangles());
}

TEST(MeshIo, WriteRefusesOtherExtensions) {
  TempDir dir;
  EXPECT_THROW(write_mesh(dir.file("x.off"), box_mesh(Vec3::Ones())), InputError);
  EXPECT_THROW(write_mesh(dir.file("no/such/folder/x.obj"), box_mesh(Vec3::Ones())), InputError);
}

}  // namespace
}  // namespace jelly
