// jelly mesh IN.stl -o OUT.msh [--size h]: fills a closed surface with tetrahedra (Gmsh) for the
// tetmesh body kind.
#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>
#include <jelly/geometry/detail/tetrahedralize.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

int mesh_command(const MeshArgs& args) {
  namespace fs = std::filesystem;
  const std::string ext = fs::path(args.output).extension().string();
  require(ext == ".msh", "-o", "\"" + args.output + "\"", "a Gmsh file name ending in .msh");
  std::error_code error;
  if (fs::exists(args.output, error)) {
    // The same file also through symbolic and hard links.
    if (fs::equivalent(args.output, args.input, error)) {
      throw InputError("-o " + args.output + " is the input surface " + args.input +
                       " (the same file): it would be overwritten; choose another name");
    }
    if (!args.overwrite) {
      throw InputError("-o " + args.output +
                       " exists (a file this command did not create): pass --overwrite to "
                       "replace it, or choose another name");
    }
  }
  const MeshFile surface = read_mesh(args.input, "IN");
  const TetMesh mesh = tetrahedralize(surface.mesh, args.size, "IN", args.input, "--size");
  write_msh(args.output, mesh);
  Real volume = 0;
  for (const Tet& t : mesh.tets) {
    const Vec3& a = mesh.vertices[t[0]];
    volume += std::abs((mesh.vertices[t[1]] - a)
                           .dot((mesh.vertices[t[2]] - a).cross(mesh.vertices[t[3]] - a))) /
              6;
  }
  std::printf("%s: %d vertices, %d tetrahedra, %zu unique edges, volume %.6g\n",
              args.output.c_str(), mesh.num_vertices(), mesh.num_tets(),
              tet_edges(mesh.tets).size(), volume);
  return kExitOk;
}

}  // namespace jelly::cli
