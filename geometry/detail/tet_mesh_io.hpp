#pragma once
// Tetrahedral meshes from and to files, read as data (no Gmsh script runs): Gmsh .msh (ASCII
// MSH 2.2 and 4.1, binary 4.1) and TetGen .node/.ele.
#include <string>

#include <jelly/geometry/detail/tetmesh.hpp>

namespace jelly {

// Reads a Gmsh mesh (.msh: MSH 4.1, ASCII or binary, or ASCII 2.2, with our own reader: a file of
// Gmsh script is refused, never run) or a TetGen mesh (`path` naming its .node or .ele file; both
// must exist). Vertices no tet uses are dropped. Groups: each Gmsh physical group (any dimension;
// by its name, or "physical_<dim>_<tag>" when it has none) as the vertices of its elements; TetGen
// regions (the .ele's first attribute) as "region_<a>" and non-zero boundary markers of the .node
// as "marker_<m>". Throws InputError naming `field` and the file for a missing, unreadable or
// non-regular file, a file the reader refuses (a binary MSH 2 file, text outside its sections, a
// count larger than the file could hold, an index out of range), 3D elements other than 4-node
// tetrahedra, and what validate_tet_mesh refuses.
TetMesh read_tet_mesh(const std::string& path, const std::string& field);

// Writes a tet mesh as Gmsh .msh 4.1 (ASCII): the tets as volume 1 (physical group "volume"),
// the boundary triangles as surface 1 (physical group "boundary"); vertex groups are not
// written. Throws InputError when the path does not end in .msh, std::runtime_error naming it
// when it cannot be written; the file is written beside and renamed, so a failed write leaves an
// existing file as it was.
void write_msh(const std::string& path, const TetMesh& mesh);

}  // namespace jelly
