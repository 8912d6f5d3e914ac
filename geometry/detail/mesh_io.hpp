#pragma once
// Triangle meshes from files (OBJ, STL, PLY) for the bodies made of them: read, welded by
// position, with named vertex groups, and checked (finite, manifold, consistently oriented,
// closed or with holes reported); and written back (tests, tools).
#include <string>
#include <vector>

#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly {

// Vertices of a mesh chosen by name: an OBJ file's `o` and `g` names (an STL solid's name).
struct VertexGroup {
  std::string name;
  std::vector<int> vertices;  // sorted, each once
};

struct MeshFile {
  TriangleMesh mesh;
  std::vector<VertexGroup> groups;
};

// A hole of an open mesh: a loop of edges that belong to one triangle only.
struct MeshHole {
  std::vector<int> vertices;   // in loop order
  Real diameter = 0;           // diagonal of the loop's bounding box (mesh units)
  Vec3 centre = Vec3::Zero();  // centre of the loop's bounding box
};

// How a mesh's edges meet.
struct MeshTopology {
  int edges = 0;                // distinct undirected edges
  int boundary_edges = 0;       // used by one triangle: the edges of holes
  int non_manifold_edges = 0;   // used by more than two triangles
  int misoriented_edges = 0;    // used twice in the same direction (neighbours disagree)
  std::vector<MeshHole> holes;  // the boundary edges as loops
  int first_non_manifold_edge[2] = {-1, -1};  // its vertices, for messages
  int first_misoriented_edge[2] = {-1, -1};

  bool closed() const { return boundary_edges == 0; }
  bool manifold() const { return non_manifold_edges == 0 && misoriented_edges == 0; }
};

MeshTopology mesh_topology(const TriangleMesh& mesh);

// Reads a .obj, .stl (ASCII or binary) or .ply file (the extension decides, in any case).
// Vertices at exactly the same position are merged (STL and, with assimp, every format repeats
// them per triangle), triangles that repeat a vertex are dropped, polygons are split into
// triangles. Named parts of the file become vertex groups. Throws InputError naming `field` and
// the file for a missing or unreadable file, another extension, a file the reader refuses, a
// mesh with no triangle, a non-finite coordinate, an edge shared by more than two triangles and
// triangles whose orientations disagree. Holes are allowed here: the caller decides (see
// require_small_holes).
MeshFile read_mesh(const std::string& path, const std::string& field);

// Throws InputError naming `field` = "`file`" unless the mesh is closed or every hole has a
// diameter of at most `max_hole_diameter` (then `what_fills` says what fills them).
void require_small_holes(const MeshTopology& topology, Real max_hole_diameter,
                         const std::string& field, const std::string& file,
                         const std::string& what_fills);

// Writes `mesh` as .obj, .stl (binary) or .ply (ASCII), chosen by the extension. Throws
// InputError naming the path for another extension or a file that cannot be written.
void write_mesh(const std::string& path, const TriangleMesh& mesh);

}  // namespace jelly
