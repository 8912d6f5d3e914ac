#include <jelly/geometry/tet_mesh_io.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gmsh.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/gmsh_session.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>

namespace jelly {

namespace {

using detail::lower_extension;
using detail::quoted;
using detail::require_mesh_file;

TetMesh read_gmsh(const std::string& path, const std::string& field) {
  const std::string value = quoted(path);
  detail::GmshSession session;
  const auto fail = [&](const std::string& why) {
    throw InputError(field, value, "a mesh file Gmsh reads: " + why);
  };
  try {
    gmsh::open(path);
  } catch (const std::string& e) {
    fail(e);
  } catch (const std::exception& e) {
    fail(e.what());
  }
  if (const std::string e = session.last_error(); !e.empty()) fail(e);

  return session.tet_mesh(field, value);
}

// The non-comment lines of a TetGen file, split into words.
class TetgenLines {
 public:
  TetgenLines(const std::string& path, const std::string& field, const std::string& value)
      : in_(path), path_(path), field_(field), value_(value) {}

  std::istringstream next(const char* what) {
    std::string text;
    while (std::getline(in_, text)) {
      ++line_;
      const std::size_t hash = text.find('#');
      if (hash != std::string::npos) text.resize(hash);
      if (text.find_first_not_of(" \t\r") != std::string::npos) return std::istringstream(text);
    }
    fail(std::string("a ") + what + ", found the end of the file");
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(field_, value_,
                     "a TetGen mesh: " + path_ + " line " + std::to_string(line_) + ": " + why);
  }

 private:
  std::ifstream in_;
  std::string path_, field_, value_;
  int line_ = 0;
};

TetMesh read_tetgen(const std::string& path, const std::string& field) {
  const std::string value = quoted(path);
  const std::filesystem::path base = std::filesystem::path(path).replace_extension();
  const std::string node_path = base.string() + ".node", ele_path = base.string() + ".ele";
  require_mesh_file(node_path, field, value);
  require_mesh_file(ele_path, field, value);

  TetMesh mesh;
  std::map<long, std::vector<int>> markers, regions;
  long first_index = 0;
  {
    TetgenLines lines(node_path, field, value);
    long count = 0;
    int dim = 0, attributes = 0, has_marker = 0;
    if (!(lines.next("header") >> count >> dim >> attributes >> has_marker) || count < 0 ||
        dim != 3 || attributes < 0 || (has_marker != 0 && has_marker != 1)) {
      lines.fail("a header '<points> 3 <attributes> <0|1>'");
    }
    require(count <= (1L << 28), field, value, "a mesh of at most 2^28 vertices");
    mesh.vertices.resize(count);
    for (long i = 0; i < count; ++i) {
      std::istringstream line = lines.next("vertex");
      long index;
      Vec3 p;
      if (!(line >> index >> p.x() >> p.y() >> p.z())) lines.fail("'<index> <x> <y> <z>'");
      if (i == 0) first_index = index;
      if (index != first_index + i) lines.fail("vertices numbered in order from 0 or 1");
      double skip;
      for (int a = 0; a < attributes; ++a) line >> skip;
      long marker = 0;
      if (has_marker == 1 && (line >> marker) && marker != 0) markers[marker].push_back(i);
      mesh.vertices[i] = p;
    }
  }
  {
    TetgenLines lines(ele_path, field, value);
    long count = 0;
    int nodes = 0, attributes = 0;
    if (!(lines.next("header") >> count >> nodes >> attributes) || count < 0 ||
        (nodes != 4 && nodes != 10) || attributes < 0) {
      lines.fail("a header '<tetrahedra> <4|10> <attributes>'");
    }
    require(count <= (1L << 28), field, value, "a mesh of at most 2^28 tetrahedra");
    mesh.tets.resize(count);
    for (long i = 0; i < count; ++i) {
      std::istringstream line = lines.next("tetrahedron");
      long index, c[10];
      line >> index;
      for (int k = 0; k < nodes; ++k) line >> c[k];
      if (!line) lines.fail("'<index> <" + std::to_string(nodes) + " vertex indices>'");
      if (nodes == 10) lines.fail("4-node tetrahedra (this file has 10-node ones)");
      for (int k = 0; k < 4; ++k) {
        const long v = c[k] - first_index;
        if (v < 0 || v >= mesh.num_vertices()) {
          lines.fail("vertex index " + std::to_string(c[k]) + " out of range");
        }
        mesh.tets[i][k] = static_cast<int>(v);
      }
      double region;
      if (attributes > 0 && (line >> region)) {
        for (int k = 0; k < 4; ++k) regions[std::lround(region)].push_back(mesh.tets[i][k]);
      }
    }
  }
  const auto add = [&](const std::string& prefix, std::map<long, std::vector<int>>& groups) {
    for (auto& [key, vertices] : groups) {
      std::sort(vertices.begin(), vertices.end());
      vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
      mesh.groups.push_back({prefix + std::to_string(key), std::move(vertices)});
    }
  };
  add("region_", regions);
  add("marker_", markers);
  return mesh;
}

}  // namespace

TetMesh read_tet_mesh(const std::string& path, const std::string& field) {
  const std::string ext = lower_extension(path);
  const std::string value = quoted(path);
  require(ext == ".msh" || ext == ".node" || ext == ".ele", field, value,
          "a tetrahedral mesh file ending in .msh (Gmsh) or .node/.ele (TetGen)");
  TetMesh mesh;
  if (ext == ".msh") {
    require_mesh_file(path, field, value);
    mesh = read_gmsh(path, field);
  } else {
    mesh = read_tetgen(path, field);
  }
  drop_unused_vertices(mesh);
  validate_tet_mesh(mesh, field, path);
  return mesh;
}

void write_msh(const std::string& path, const TetMesh& mesh) {
  require(lower_extension(path) == ".msh", "mesh file", quoted(path), "a file ending in .msh");
  std::ofstream out(path);
  require(static_cast<bool>(out), "mesh file", quoted(path), "a file that can be written");
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
  require(static_cast<bool>(out.flush()), "mesh file", quoted(path), "a file that can be written");
}

}  // namespace jelly
