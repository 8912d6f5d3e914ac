#include <jelly/geometry/detail/tet_mesh_io.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>
#include <jelly/geometry/detail/msh_reader.hpp>
#include <jelly/geometry/detail/tetgen_reader.hpp>

namespace jelly {

using detail::lower_extension;
using detail::quoted;
using detail::require_mesh_file;

TetMesh read_tet_mesh(const std::string& path, const std::string& field) {
  const std::string ext = lower_extension(path);
  const std::string value = quoted(path);
  require(ext == ".msh" || ext == ".node" || ext == ".ele", field, value,
          "a tetrahedral mesh file ending in .msh (Gmsh) or .node/.ele (TetGen)");
  TetMesh mesh;
  if (ext == ".msh") {
    require_mesh_file(path, field, value);
    mesh = detail::read_msh(path, field);
  } else {
    mesh =
        detail::read_tetgen(std::filesystem::path(path).replace_extension().string(), field, value);
  }
  drop_unused_vertices(mesh);
  validate_tet_mesh(mesh, field, path);
  return mesh;
}

void write_msh(const std::string& path, const TetMesh& mesh) {
  require(lower_extension(path) == ".msh", "mesh file", quoted(path), "a file ending in .msh");
  std::ostringstream out;
  out.precision(17);
  const std::vector<Triangle> boundary = tet_boundary(mesh.tets, mesh.vertices);
  std::vector<char> on_boundary(mesh.vertices.size(), 0);
  for (const Triangle& t : boundary) {
    for (int c : t) on_boundary[c] = 1;
  }
  Eigen::AlignedBox3d box;
  for (const Vec3& v : mesh.vertices) box.extend(v);
  const auto bounds = [&] {
    std::ostringstream s;
    s.precision(17);
    s << box.min().x() << ' ' << box.min().y() << ' ' << box.min().z() << ' ' << box.max().x()
      << ' ' << box.max().y() << ' ' << box.max().z();
    return s.str();
  };
  const std::size_t n = mesh.vertices.size();
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$PhysicalNames\n2\n2 1 \"boundary\"\n3 2 \"volume\"\n$EndPhysicalNames\n";
  // No points or curves; surface 1 (physical 1, no bounding curves); volume 1 (physical 2,
  // bounded by surface 1).
  out << "$Entities\n0 0 1 1\n";
  out << "1 " << bounds() << " 1 1 0\n";
  out << "1 " << bounds() << " 1 2 1 1\n$EndEntities\n";
  // Boundary vertices on the surface, the others inside the volume; node tag = index + 1.
  std::size_t on = 0;
  for (char b : on_boundary) on += b;
  out << "$Nodes\n2 " << n << " 1 " << n << "\n";
  for (int pass = 0; pass < 2; ++pass) {
    const bool surface = pass == 0;
    out << (surface ? "2 1 0 " : "3 1 0 ") << (surface ? on : n - on) << "\n";
    for (std::size_t v = 0; v < n; ++v) {
      if ((on_boundary[v] != 0) == surface) out << v + 1 << "\n";
    }
    for (std::size_t v = 0; v < n; ++v) {
      if ((on_boundary[v] != 0) == surface) {
        const Vec3& p = mesh.vertices[v];
        out << p.x() << ' ' << p.y() << ' ' << p.z() << "\n";
      }
    }
  }
  out << "$EndNodes\n";
  const std::size_t elements = boundary.size() + mesh.tets.size();
  out << "$Elements\n2 " << elements << " 1 " << elements << "\n";
  out << "2 1 2 " << boundary.size() << "\n";
  std::size_t tag = 1;
  for (const Triangle& t : boundary) {
    out << tag++ << ' ' << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << "\n";
  }
  out << "3 1 4 " << mesh.tets.size() << "\n";
  for (const Tet& t : mesh.tets) {
    out << tag++ << ' ' << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << ' ' << t[3] + 1
        << "\n";
  }
  out << "$EndElements\n";
  detail::replace_file(path, out.str());
}

}  // namespace jelly
