#pragma once
// The reader of triangle-mesh files (.obj, .stl, .ply) that read_mesh calls once its own checks
// pass: registered by the meshes component (assimp); without it read_mesh says the component is
// missing.
#include <map>
#include <string>
#include <vector>

#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly::detail {

// Reads `path` into `mesh` (vertices at one position welded into one, triangles that repeat a
// vertex dropped: returns how many) and the named parts into `groups` (name -> triangle
// corners, in any order, repeats allowed). Throws InputError(field, value, ...) for a file it
// refuses.
using MeshFileReader = int (*)(const std::string& path, const std::string& field,
                               const std::string& value, TriangleMesh& mesh,
                               std::map<std::string, std::vector<int>>& groups);

// The registered reader, or null.
MeshFileReader mesh_file_reader();
void set_mesh_file_reader(MeshFileReader reader);

}  // namespace jelly::detail
