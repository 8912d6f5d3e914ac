// Fuzz target: the triangle mesh readers (OBJ, STL ASCII and binary, PLY through assimp). The
// first byte chooses the extension, the rest is the file. Any file is either an InputError or a
// mesh whose triangles index existing vertices, with finite coordinates; a mesh that reads is
// then used as the bodies and obstacles use it: its topology, a lattice filled from it (at a
// spacing giving at most a few thousand points) and distances from a mesh obstacle.
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_distance.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/detail/voxelized.hpp>

#include "fuzz/fuzz_file.hpp"
#include "fuzz/fuzz_target.hpp"

namespace jelly::fuzz {

void check_mesh(const MeshFile& file) {
  const TriangleMesh& mesh = file.mesh;
  if (mesh.triangles.empty()) fail("a mesh without triangles was read");
  for (const Vec3& v : mesh.vertices) {
    if (!v.allFinite()) fail("a vertex that is not finite was read");
  }
  for (const Triangle& t : mesh.triangles) {
    for (int corner : t) {
      if (corner < 0 || corner >= mesh.num_vertices()) {
        fail("triangle index " + std::to_string(corner) + " of " +
             std::to_string(mesh.num_vertices()) + " vertices");
      }
    }
  }
  for (const VertexGroup& g : file.groups) {
    for (int v : g.vertices) {
      if (v < 0 || v >= mesh.num_vertices())
        fail("group " + g.name + " has vertex " + std::to_string(v));
    }
  }
}

void use_mesh(const TriangleMesh& mesh) {
  mesh_topology(mesh);
  const Eigen::AlignedBox3d box = mesh.bounds();
  const Real diagonal = box.diagonal().norm();
  if (mesh.num_triangles() > 2000 || !(diagonal > 1e-6 && diagonal < 1e6)) return;
  const Real spacing = diagonal / 12;  // at most 13^3 lattice points
  try {
    voxelize(mesh, spacing);
  } catch (const InputError&) {
  }
  const MeshDistance distance(mesh);
  const Vec3 probes[] = {box.center(), box.min() - Vec3::Constant(spacing), box.max()};
  for (const Vec3& q : probes) {
    const Real d = distance.query(q).distance;
    if (std::isnan(d)) fail("a mesh distance is NaN");
  }
}

}  // namespace jelly::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly;
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".obj", ".stl", ".ply"};
  const std::string path =
      fuzz::write_scratch(std::string("mesh") + kExtensions[data[0] % 3],
                          std::string(reinterpret_cast<const char*>(data) + 1, size - 1));
  MeshFile file;
  try {
    file = read_mesh(path, "file");
  } catch (const InputError&) {
    return 0;
  }
  fuzz::check_mesh(file);
  fuzz::use_mesh(file.mesh);
  return 0;
}
