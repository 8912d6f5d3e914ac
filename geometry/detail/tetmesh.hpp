#pragma once
// Body kind "tetmesh": springs along the unique edges of a tetrahedral mesh (Gmsh .msh, TetGen
// .node/.ele), particle masses lumped from the tets' volumes, the boundary triangles as render
// surface.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/detail/pose.hpp>

namespace jelly {

using Tet = std::array<int, 4>;

// A tetrahedral mesh: vertices, tetrahedra over them, named groups of vertices.
struct TetMesh {
  std::vector<Vec3> vertices;
  std::vector<Tet> tets;
  std::vector<VertexGroup> groups;  // Gmsh physical groups, TetGen regions and markers

  int num_vertices() const { return static_cast<int>(vertices.size()); }
  int num_tets() const { return static_cast<int>(tets.size()); }
};

// Throws InputError naming `field` = "`file`" unless there is a tet, every index is in range,
// every coordinate finite, every tet has a volume above 1e-12 times its longest edge cubed and
// no two tets have the same vertices.
void validate_tet_mesh(const TetMesh& mesh, const std::string& field, const std::string& file);

// Removes the vertices no tet uses, renumbering the tets and the groups (a group left empty
// goes).
void drop_unused_vertices(TetMesh& mesh);

// The unique edges (a < b), sorted.
std::vector<std::array<int, 2>> tet_edges(const std::vector<Tet>& tets);
// The faces that belong to one tet only, counter-clockwise seen from outside the mesh (away
// from the tet's fourth vertex).
std::vector<Triangle> tet_boundary(const std::vector<Tet>& tets, const std::vector<Vec3>& vertices);

// The body of a tet mesh placed by `pose`: one particle per vertex; one structural spring per
// unique edge (a tet with its 6 edges is rigid, so no shear or bending springs are needed; the
// material's structural coefficients apply to all); masses lumped, a quarter of each tet's
// density x volume to each of its vertices (density > 0), else particle_mass each; the boundary
// triangles as surface; the mesh's groups as particle groups. Throws InputError naming
// `prefix`file for an invalid mesh.
BodyPart build_tetmesh(const TetMesh& mesh, const Pose& pose, const Material& material,
                       const std::string& prefix);

// Body kind "tetmesh": keys file (.msh, or TetGen's .node/.ele; relative to the scene file's
// folder), scale, rotation_degrees, position. The mesh is read when the shape is validated
// (once per file name; copies share it).
struct TetmeshShape final : BodyShapeOf<TetmeshShape> {
  std::string file;  // absolute, or relative to the current directory
  Pose pose;

  std::string_view kind() const override { return "tetmesh"; }
  // Also reads the mesh (InputError naming `prefix`file for a missing or bad one).
  void validate(const std::string& prefix) const override;
  BodyPart build(const Material& material, const std::string& prefix) const override;
  long estimated_particles() const override;
  long estimated_springs() const override;  // the mesh's unique edges, exactly
  void write(Json& object) const override;
  static std::unique_ptr<BodyShape> read(JsonFields& fields);

  // The mesh as read (validate() or the first call reads it).
  const TetMesh& mesh(const std::string& prefix = "") const;

 private:
  struct Cache;
  mutable std::shared_ptr<const Cache> cache_;
};

}  // namespace jelly
