#pragma once
// Filling a closed triangle surface with tetrahedra (Gmsh's Delaunay mesher): what
// `jelly mesh IN.stl -o OUT.msh` does.
#include <string>

#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly {

// Tetrahedralizes the inside of a closed, consistently oriented surface. `size` = 0 keeps the
// surface's triangles as the boundary and lets Gmsh grade the inside from them; > 0 remeshes
// the surface first with elements of about that size. Groups: "boundary" (the surface's
// vertices). Throws InputError naming `field` = `name` (the surface's file, say) for a surface
// that is open or non-manifold, or that Gmsh cannot fill (a self-intersecting one), with Gmsh's
// reason, and naming `size_field` for a negative size.
TetMesh tetrahedralize(const TriangleMesh& surface, Real size, const std::string& field,
                       const std::string& name = "the surface",
                       const std::string& size_field = "size");

// "" when this build can tetrahedralize, otherwise why not (built without Gmsh, or its plugin
// libjelly_gmsh missing). Loads Gmsh to find out, which takes a moment.
std::string tetrahedralize_unavailable_reason();

}  // namespace jelly
