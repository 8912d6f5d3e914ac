#include <jelly/geometry/body_shape.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/box.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/geometry/detail/voxelized.hpp>

namespace jelly {

const std::vector<BodyKindInfo>& body_kinds() {
  static const std::vector<BodyKindInfo> kinds{
      {"box", "a lattice filling a box: nx, ny, nz, size, position (centre), rotation_degrees",
       &BoxShape::read},
      {"cloth",
       "a sheet in its local x-z plane: nu, nv, size_u, size_v, position, rotation_degrees",
       &ClothShape::read},
      {"cube", "the seed's lattice: n per edge, edge_length, origin (corner particle)",
       &CubeShape::read},
      {"tetmesh",
       "springs along a tet mesh's edges: file (.msh, .node/.ele), scale, position, "
       "rotation_degrees",
       &TetmeshShape::read},
      {"voxelized",
       "a closed mesh filled with the lattice: file (.obj/.stl/.ply), spacing, scale, position, "
       "rotation_degrees",
       &VoxelizedShape::read},
  };
  return kinds;
}

const BodyKindInfo& find_body_kind(std::string_view name, const std::string& field) {
  std::string known;
  for (const BodyKindInfo& k : body_kinds()) {
    if (k.name == name) return k;
    known += (known.empty() ? "\"" : ", \"") + std::string(k.name) + "\"";
  }
  throw InputError(field, "\"" + std::string(name) + "\"", "one of " + known);
}

}  // namespace jelly
