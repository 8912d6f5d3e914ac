#include <jelly/geometry/tetrahedralize.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/gmsh_plugin.hpp>
#include <jelly/geometry/mesh_io.hpp>

namespace jelly {

TetMesh tetrahedralize(const TriangleMesh& surface, Real size, const std::string& field,
                       const std::string& name, const std::string& size_field) {
  const std::string value = "\"" + name + "\"";
  require(std::isfinite(size) && size >= 0, size_field, size,
          "a finite element size >= 0 (0 = keep the surface's triangles)");
  require(surface.num_triangles() > 0, field, value, "a surface with at least one triangle");
  const MeshTopology topo = mesh_topology(surface);
  require(topo.manifold(), field, value,
          "a manifold, consistently oriented surface (each edge in two triangles running through "
          "it in opposite directions)");
  require_small_holes(topo, 0, field, name, "Gmsh fills only closed surfaces");

  TetMesh mesh = detail::gmsh_fill()(surface, size, field, value);
  drop_unused_vertices(mesh);
  if (mesh.tets.empty()) {
    throw InputError(field, value, "a surface Gmsh can fill with tetrahedra: Gmsh made none");
  }
  validate_tet_mesh(mesh, field, value);
  return mesh;
}

std::string tetrahedralize_unavailable_reason() { return detail::gmsh_unavailable_reason(); }

}  // namespace jelly
