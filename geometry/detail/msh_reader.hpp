#pragma once
// Gmsh's MSH files (ASCII 2.2 and 4.1, binary 4.1) read as data, without Gmsh: nodes, 4-node
// tetrahedra and physical groups; a line of Gmsh script is refused, never run. Internal to
// geometry/.
#include <string>

#include <jelly/geometry/detail/tetmesh.hpp>

namespace jelly::detail {

// The tetrahedra of an MSH file with their nodes (in increasing tag order) and its physical groups
// (sorted by dimension and tag; by name, or "physical_<dim>_<tag>") as the nodes of their
// elements. Sections other than $MeshFormat, $PhysicalNames, $Entities (4.1), $Nodes and
// $Elements are skipped when they are data (comments, node and element data, periodic links) and
// refused otherwise. Throws InputError(field, "`path`", ...) naming the line for anything else: a
// binary MSH 2 file (or a binary 4.1 file of another byte order), another version, text outside a
// section (Gmsh script such as Merge or SystemCall), a count larger than the file could hold, a
// node named twice or missing, elements Gmsh does not define and 3D elements other than 4-node
// tetrahedra. The file is the caller's to check first (require_mesh_file).
TetMesh read_msh(const std::string& path, const std::string& field);

}  // namespace jelly::detail
