#pragma once
// TetGen's .node/.ele files read as data, every count and index checked before use. Internal to
// geometry/.
#include <string>

#include <jelly/geometry/detail/tetmesh.hpp>

namespace jelly::detail {

// The tetrahedra of `base`.node and `base`.ele (numbered from 0 or 1) with their vertices;
// groups: regions (the .ele's first attribute) as "region_<a>" and non-zero boundary markers of
// the .node as "marker_<m>". Throws InputError(field, value, ...) naming the file and the line
// for a missing file, a count larger than the file could hold, a line without the fields its
// header promises, an index out of range and 10-node tetrahedra.
TetMesh read_tetgen(const std::string& base, const std::string& field, const std::string& value);

}  // namespace jelly::detail
