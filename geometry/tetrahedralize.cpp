#include <jelly/geometry/detail/tetrahedralize.hpp>

#include <cmath>
#include <sstream>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/gmsh_plugin.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>

namespace jelly {

namespace {

// More tetrahedra than this would take Gmsh many gigabytes and hours: refused before it starts.
constexpr double kMaxTetrahedra = 1e7;

// Gmsh fills a volume V with elements of size h with about V / (h^3 / (6 sqrt 2)) tetrahedra
// (the volume of a regular one): the estimate a size is checked against.
double tetrahedra_estimate(Real volume, Real size) {
  return volume / (size * size * size / (6 * std::sqrt(2.0)));
}

// A figure for a message: three significant digits.
std::string approx(double x) {
  std::ostringstream out;
  out.precision(3);
  out << x;
  return out.str();
}

}  // namespace

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
  if (size > 0) {
    const Real volume = std::abs(surface.enclosed_volume());
    const double estimate = tetrahedra_estimate(volume, size);
    if (estimate > kMaxTetrahedra) {
      const double smallest = std::cbrt(volume * 6 * std::sqrt(2.0) / kMaxTetrahedra);
      throw InputError(size_field, to_text(size),
                       "an element size that fills " + name + " (volume " + approx(volume) +
                           ") with at most " + approx(kMaxTetrahedra) +
                           " tetrahedra: this one would make about " + approx(estimate) +
                           "; the smallest size allowed is about " + approx(smallest));
    }
  }

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
