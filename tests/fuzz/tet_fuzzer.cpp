// Fuzz target: the tet mesh readers, Gmsh .msh (ASCII 2.2 and 4.1, binary 4.1) and TetGen
// .node/.ele. The first byte chooses the reader; for TetGen the rest is split at the first
// "\n##ele\n" into the .node and the .ele file. Any file is either an InputError or a mesh that
// validate_tet_mesh accepts (indices in range, finite, no flat or repeated tet) and whose groups
// name existing vertices; such a mesh then builds a tetmesh body.
#include <cstddef>
#include <cstdint>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>

#include "fuzz/fuzz_file.hpp"
#include "fuzz/fuzz_target.hpp"

namespace jelly::fuzz {

void check_tet_mesh(const TetMesh& mesh) {
  try {
    validate_tet_mesh(mesh, "file", "fuzz");
  } catch (const InputError& e) {
    fail(std::string("read_tet_mesh returned a mesh validate_tet_mesh refuses: ") + e.what());
  }
  for (const VertexGroup& g : mesh.groups) {
    for (int v : g.vertices) {
      if (v < 0 || v >= mesh.num_vertices())
        fail("group " + g.name + " has vertex " + std::to_string(v));
    }
  }
  if (mesh.num_tets() > 20000) return;  // keep each input fast
  try {
    Material material;
    build_tetmesh(mesh, Pose{}, material, "bodies[0].");
  } catch (const InputError&) {
  }
}

}  // namespace jelly::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly;
  if (size < 1) return 0;
  const std::string rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::string path;
  if (data[0] % 2 == 0) {
    path = fuzz::write_scratch("mesh.msh", rest);
  } else {
    const std::string separator = "\n##ele\n";
    const std::size_t at = rest.find(separator);
    const std::string node = at == std::string::npos ? rest : rest.substr(0, at);
    const std::string ele = at == std::string::npos ? "" : rest.substr(at + separator.size());
    path = fuzz::write_scratch("mesh.node", node);
    fuzz::write_scratch("mesh.ele", ele);
  }
  TetMesh mesh;
  try {
    mesh = read_tet_mesh(path, "file");
  } catch (const InputError&) {
    return 0;
  }
  fuzz::check_tet_mesh(mesh);
  return 0;
}
