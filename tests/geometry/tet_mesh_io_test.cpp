// Tet mesh files read as data: Gmsh MSH 2.2 and 4.1 (ASCII; 4.1 binary) without Gmsh, TetGen
// .node/.ele, and every count, index and line of a hostile file refused naming the field.
#include <cstdint>
#include <filesystem>
#include <map>

#include <sys/stat.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/geometry/detail/tet_mesh_io.hpp>

#include "geometry_support.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using testing::input_error;
using testing::TempDir;
using testing::write_text;

// The unit cube split into 5 tets, as MSH 2.2: tags out of order and a gap, a physical surface
// (one triangle) and a physical volume with names, and one without a name.
constexpr const char* kCubeMsh22 =
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
    "$PhysicalNames\n2\n2 7 \"bottom face\"\n3 9 \"volume\"\n$EndPhysicalNames\n"
    "$Comments\nSystemCall \"touch /never\"; anything in a comment is skipped\n$EndComments\n"
    "$Nodes\n8\n"
    "10 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n5 0 0 1\n6 1 0 1\n7 0 1 1\n8 1 1 1\n"
    "$EndNodes\n"
    "$Elements\n7\n"
    "1 2 2 7 1 10 3 2\n"
    "2 4 2 9 1 10 2 3 5\n3 4 2 9 1 4 3 2 8\n4 4 2 9 1 6 2 5 8\n5 4 2 9 1 7 5 3 8\n"
    "6 4 2 9 1 2 3 5 8\n"
    "7 15 2 3 1 8\n"
    "$EndElements\n";

// The same cube as MSH 4.1, with entities carrying the physical tags and a parametric block.
constexpr const char* kCubeMsh41 =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    "$PhysicalNames\n1\n3 2 \"volume\"\n$EndPhysicalNames\n"
    "$Entities\n1 0 1 1\n"
    "1 1 1 1 1 1\n"
    "1 0 0 0 1 1 0 1 5 0\n"
    "1 0 0 0 1 1 1 1 2 1 1\n"
    "$EndEntities\n"
    "$Nodes\n3 8 1 8\n"
    "0 1 0 1\n8\n1 1 1\n"
    "2 1 1 3\n1\n2\n3\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n"
    "3 1 0 4\n4\n5\n6\n7\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n"
    "$EndNodes\n"
    "$Elements\n3 7 1 7\n"
    "0 1 15 1\n7 8\n"
    "2 1 2 1\n6 1 2 3\n"
    "3 1 4 5\n1 1 2 3 5\n2 4 3 2 8\n3 6 2 5 8\n4 7 5 3 8\n5 2 3 5 8\n"
    "$EndElements\n";

// The unit cube's 5 tets as binary MSH 4.1 (little-endian), its volume in physical group 2; with
// `nodes` as the node count of the section's header.
std::string cube_binary_msh41(std::uint64_t nodes = 8) {
  std::string b = "$MeshFormat\n4.1 1 8\n";
  const auto i32 = [&](std::int32_t v) { b.append(reinterpret_cast<const char*>(&v), 4); };
  const auto u64 = [&](std::uint64_t v) { b.append(reinterpret_cast<const char*>(&v), 8); };
  const auto f64 = [&](double v) { b.append(reinterpret_cast<const char*>(&v), 8); };
  i32(1);
  b += "\n$EndMeshFormat\n$Entities\n";
  for (std::uint64_t c : {0, 0, 0, 1}) u64(c);
  i32(1);
  for (double v : {0, 0, 0, 1, 1, 1}) f64(v);
  u64(1);
  i32(2);
  u64(0);
  b += "\n$EndEntities\n$Nodes\n";
  for (std::uint64_t v : {std::uint64_t{1}, nodes, std::uint64_t{1}, std::uint64_t{8}}) u64(v);
  i32(3), i32(1), i32(0), u64(8);
  for (int t = 1; t <= 8; ++t) u64(t);
  for (int c = 0; c < 8; ++c) f64(c & 1), f64((c >> 1) & 1), f64((c >> 2) & 1);
  b += "\n$EndNodes\n$Elements\n";
  for (std::uint64_t v : {1, 5, 1, 5}) u64(v);
  i32(3), i32(1), i32(4), u64(5);
  const int tets[5][4] = {{1, 2, 3, 5}, {4, 3, 2, 8}, {6, 2, 5, 8}, {7, 5, 3, 8}, {2, 3, 5, 8}};
  for (int e = 0; e < 5; ++e) {
    u64(e + 1);
    for (int c : tets[e]) u64(c);
  }
  b += "\n$EndElements\n";
  return b;
}

std::map<std::string, std::size_t> group_sizes(const TetMesh& m) {
  std::map<std::string, std::size_t> sizes;
  for (const VertexGroup& g : m.groups) sizes[g.name] = g.vertices.size();
  return sizes;
}

TEST(TetMeshIo, Msh22And41AreReadWithoutGmsh) {
  TempDir dir;
  const TetMesh v2 = read_tet_mesh(write_text(dir.file("cube2.msh"), kCubeMsh22), "file");
  EXPECT_EQ(v2.num_vertices(), 8);
  EXPECT_EQ(v2.num_tets(), 5);
  // Vertices in increasing tag order: tag 10 (the origin) is the last.
  EXPECT_EQ(v2.vertices.back(), Vec3(0, 0, 0));
  EXPECT_EQ(group_sizes(v2), (std::map<std::string, std::size_t>{
                                 {"bottom face", 3}, {"volume", 8}, {"physical_0_3", 1}}));
  EXPECT_EQ(v2.groups[0].name, "physical_0_3");  // by dimension, then tag
  const TetMesh v4 = read_tet_mesh(write_text(dir.file("cube4.msh"), kCubeMsh41), "file");
  EXPECT_EQ(v4.num_vertices(), 8);
  EXPECT_EQ(v4.num_tets(), 5);
  EXPECT_EQ(v4.vertices[0], Vec3(0, 0, 0));
  EXPECT_EQ(group_sizes(v4), (std::map<std::string, std::size_t>{
                                 {"physical_0_1", 1}, {"physical_2_5", 3}, {"volume", 8}}));
  const TetMesh binary =
      read_tet_mesh(write_text(dir.file("cube_bin.msh"), cube_binary_msh41()), "file");
  EXPECT_EQ(binary.vertices, v4.vertices);
  EXPECT_EQ(binary.tets, v4.tets);
  EXPECT_EQ(group_sizes(binary), (std::map<std::string, std::size_t>{{"physical_3_2", 8}}));
}

// A file of Gmsh script named .msh runs nothing, reads no other file and does not hang.
TEST(TetMeshIo, GmshScriptInAMshFileIsRefusedNotRun) {
  TempDir dir;
  const std::string field = "bodies[0].file";
  const auto error = [&](const std::string& path) {
    return input_error([&] { read_tet_mesh(path, field); });
  };
  const std::string touched = dir.file("touched");
  for (const std::string& text :
       {"SystemCall \"touch " + touched + "\";\n",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\nSystemCall \"touch " + touched + "\";\n",
        "// a comment\nSystemCall \"touch " + touched + "\";\n"}) {
    const std::string path = write_text(dir.file("evil.msh"), text);
    const std::string message = error(path);
    EXPECT_THAT(message, HasSubstr(field + " = \"" + path + "\" is invalid"));
    EXPECT_THAT(message, HasSubstr("line "));
    EXPECT_FALSE(std::filesystem::exists(touched)) << text;
  }
  // Merge would read another file: here a valid mesh, which must not be read through it.
  write_text(dir.file("real.msh"), kCubeMsh41);
  const std::string merge =
      write_text(dir.file("merge.msh"), "Merge \"" + dir.file("real.msh") + "\";\n");
  EXPECT_THAT(error(merge), HasSubstr("line 1: a section such as $Nodes, found 'Merge'"));
  EXPECT_THAT(error(write_text(dir.file("passwd.msh"), "Merge \"/etc/passwd\";\n")),
              HasSubstr("Merge"));
  // A script loop returns at once with an error.
  EXPECT_THAT(error(write_text(dir.file("loop.msh"), "For (1:1e12)\nEndFor\n")),
              HasSubstr("found 'For'"));
  EXPECT_THAT(error(write_text(dir.file("while.msh"), "While(1)\nEndWhile\n")),
              HasSubstr("found 'While(1)'"));
}

TEST(TetMeshIo, MshFilesOtherThanTetMeshesAreRefusedNamingWhat) {
  TempDir dir;
  const std::string field = "bodies[0].file";
  const auto error = [&](const std::string& name, const std::string& text) {
    return input_error([&] { read_tet_mesh(write_text(dir.file(name), text), field); });
  };
  EXPECT_THAT(error("binary.msh", "$MeshFormat\n2.2 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n"),
              HasSubstr("file-type 1 (binary MSH 2): ASCII MSH 2.2 or 4.1 (file-type 0) or "
                        "binary MSH 4.1"));
  EXPECT_THAT(error("binary_count.msh", cube_binary_msh41(1ull << 40)),
              HasSubstr("found 1099511627776 (binary)"));
  std::string big_endian = cube_binary_msh41();
  std::swap(big_endian[20], big_endian[23]);  // the binary one, byte-swapped
  EXPECT_THAT(error("big_endian.msh", big_endian), HasSubstr("the binary one"));
  EXPECT_THAT(error("v3.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n"),
              HasSubstr("version 3.0: ASCII MSH 2.2 or 4.1"));
  EXPECT_THAT(error("v40.msh", "$MeshFormat\n4 0 8\n$EndMeshFormat\n"), HasSubstr("version 4"));
  EXPECT_THAT(error("noformat.msh", "$Nodes\n0\n$EndNodes\n"), HasSubstr("$MeshFormat first"));
  EXPECT_THAT(error("unknown.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Script\n$EndScript\n"),
              HasSubstr("found '$Script'"));
  EXPECT_THAT(error("unended.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Comments\nxx\n"),
              HasSubstr("$EndComments"));
  const std::string head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  // A count larger than the file could hold is refused before anything is allocated.
  EXPECT_THAT(error("count.msh", head + "$Nodes\n4000000000000\n1 0 0 0\n$EndNodes\n"),
              HasSubstr("the number of nodes (at most one per 2 bytes of the file) from 0 to 37, "
                        "found '4000000000000'"));
  EXPECT_THAT(error("negative.msh", head + "$Nodes\n-1\n$EndNodes\n"), HasSubstr("found '-1'"));
  const std::string nodes = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
  EXPECT_THAT(
      error("missing_node.msh", head + nodes + "$Elements\n1\n1 4 0 1 2 3 9\n$EndElements\n"),
      HasSubstr("node 9, which the file does not have"));
  EXPECT_THAT(error("node_twice.msh", head + "$Nodes\n2\n1 0 0 0\n1 1 0 0\n$EndNodes\n"),
              HasSubstr("node 1 twice"));
  EXPECT_THAT(
      error("hex.msh", head + nodes + "$Elements\n1\n1 5 0 1 2 3 4 1 2 3 4\n$EndElements\n"),
      HasSubstr("4-node tetrahedra (it has 3D elements of type 8-node hexahedron)"));
  EXPECT_THAT(error("type.msh", head + nodes + "$Elements\n1\n1 99 0 1\n$EndElements\n"),
              HasSubstr("element type 99"));
  EXPECT_THAT(error("short.msh", head + nodes + "$Elements\n1\n1 4 0 1 2\n$EndElements\n"),
              HasSubstr("line 14: a node tag from 1 to 9223372036854775807, found '$EndElements'"));
  EXPECT_THAT(error("twice.msh", head + nodes + nodes), HasSubstr("a second $Nodes"));
  EXPECT_THAT(
      error("dup.msh", head + nodes + "$Elements\n2\n1 4 0 1 2 3 4\n2 4 0 2 1 4 3\n$EndElements\n"),
      HasSubstr("tetrahedron appears once"));
  EXPECT_THAT(error("name.msh", head + "$PhysicalNames\n1\n3 1 volume\n$EndPhysicalNames\n"),
              HasSubstr("a name in double quotes"));
}

TEST(TetMeshIo, TetgenCountsAndIndicesAreCheckedBeforeUse) {
  TempDir dir;
  const std::string field = "bodies[0].file";
  const auto error = [&](const std::string& node, const std::string& ele) {
    write_text(dir.file("t.node"), node);
    write_text(dir.file("t.ele"), ele);
    return input_error([&] { read_tet_mesh(dir.file("t.ele"), field); });
  };
  const std::string node = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
  // An element count that would allocate gigabytes before reading a line.
  EXPECT_THAT(error(node, "268435455 4 0\n0 0 1 2 3\n"),
              HasSubstr("at most one tetrahedron per 10 bytes of the file"));
  EXPECT_THAT(error("268435455 3 0 0\n0 0 0 0\n", "1 4 0\n0 0 1 2 3\n"),
              HasSubstr("at most one vertex per 8 bytes of the file"));
  // An attribute count that is not in the file (the reader looped over 2^31 of them per line).
  EXPECT_THAT(error("4 3 2147483647 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n", "1 4 0\n0 0 1 2 3\n"),
              HasSubstr("2147483647 attributes"));
  EXPECT_THAT(error(node, "1 4 2147483647\n0 0 1 2 3\n"), HasSubstr("2147483647 attributes"));
  EXPECT_THAT(error(node, "1 4 0\n0 0 1 2 -3\n"), HasSubstr("vertex index -3 out of range"));
  EXPECT_THAT(error(node, "1 4 1\n0 0 1 2 3 1e300\n"), HasSubstr("region attribute"));
  EXPECT_THAT(error(node, "2 4 0\n0 0 1 2 3\n1 3 2 1 0\n"),
              HasSubstr("tetrahedron appears once (tets 0 and 1"));
  EXPECT_THAT(error("4 3 0 0\n7 0 0 0\n8 1 0 0\n9 0 1 0\n10 0 0 1\n", "1 4 0\n7 7 8 9 10\n"),
              HasSubstr("numbered in order from 0 or 1"));
}

TEST(TetMeshIo, NonRegularFilesAreRefused) {
  TempDir dir;
  const std::string fifo = dir.file("pipe.msh");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THAT(input_error([&] { read_tet_mesh(fifo, "file"); }), HasSubstr("a pipe"));
}

}  // namespace
}  // namespace jelly
