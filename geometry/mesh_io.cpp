#include <jelly/geometry/detail/mesh_io.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <unordered_map>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>
#include <jelly/geometry/detail/mesh_file_reader.hpp>

namespace jelly {

namespace {

using detail::lower_extension;
using detail::quoted;

}  // namespace

MeshTopology mesh_topology(const TriangleMesh& mesh) {
  MeshTopology topo;
  // Every directed edge (a, b) of every triangle, sorted by its undirected key.
  struct Directed {
    std::uint64_t key;  // min * 2^32 + max
    int a, b;
  };
  std::vector<Directed> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) {
      const int a = t[c], b = t[(c + 1) % 3];
      const auto lo = static_cast<std::uint64_t>(std::min(a, b));
      const auto hi = static_cast<std::uint64_t>(std::max(a, b));
      edges.push_back({(lo << 32) | hi, a, b});
    }
  }
  std::sort(edges.begin(), edges.end(),
            [](const Directed& x, const Directed& y) { return x.key < y.key; });
  // Boundary edges as directed a -> b, to be chained into loops.
  std::unordered_multimap<int, int> next;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    const std::size_t uses = j - i;
    ++topo.edges;
    if (uses == 1) {
      ++topo.boundary_edges;
      next.emplace(edges[i].a, edges[i].b);
    } else if (uses > 2) {
      if (topo.non_manifold_edges++ == 0) {
        topo.first_non_manifold_edge[0] = edges[i].a;
        topo.first_non_manifold_edge[1] = edges[i].b;
      }
    } else if (edges[i].a == edges[i + 1].a) {
      if (topo.misoriented_edges++ == 0) {
        topo.first_misoriented_edge[0] = edges[i].a;
        topo.first_misoriented_edge[1] = edges[i].b;
      }
    }
    i = j;
  }
  // Chain the boundary edges into loops (a vertex where several holes touch is left by any of
  // its outgoing edges: the loops then differ, their union does not).
  while (!next.empty()) {
    MeshHole hole;
    const int start = next.begin()->first;
    int at = start;
    Eigen::AlignedBox3d box;
    while (true) {
      const auto it = next.find(at);
      if (it == next.end()) break;
      hole.vertices.push_back(at);
      box.extend(mesh.vertices[at]);
      at = it->second;
      next.erase(it);
      if (at == start) break;
    }
    hole.diameter = box.isEmpty() ? 0 : box.diagonal().norm();
    hole.centre = box.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(box.center());
    topo.holes.push_back(std::move(hole));
  }
  std::sort(topo.holes.begin(), topo.holes.end(),
            [](const MeshHole& x, const MeshHole& y) { return x.diameter > y.diameter; });
  return topo;
}

MeshFile read_mesh(const std::string& path, const std::string& field) {
  namespace fs = std::filesystem;
  const std::string value = quoted(path);
  const std::string ext = lower_extension(path);
  require(ext == ".obj" || ext == ".stl" || ext == ".ply", field, value,
          "a mesh file ending in .obj, .stl or .ply");
  detail::require_mesh_file(path, field, value);
  if (ext == ".ply") detail::require_ply_counts_fit(path, field, value);
  if (ext == ".obj") detail::require_text_mesh(path, field, value, "OBJ");
  if (ext == ".stl") detail::require_text_mesh(path, field, value, "STL");

  const detail::MeshFileReader reader = detail::mesh_file_reader();
  if (reader == nullptr) {
    throw InputError(field, value,
                     "a mesh file, which this jelly cannot read: it was built without its meshes "
                     "component (JELLY_WITH_MESHES=OFF; `jelly list` shows the components)");
  }
  MeshFile out;
  std::map<std::string, std::vector<int>> groups;
  const int dropped = reader(path, field, value, out.mesh, groups);
  require(out.mesh.num_triangles() > 0, field, value,
          "a mesh with at least one triangle (it has none" +
              std::string(dropped > 0 ? ", " + std::to_string(dropped) + " degenerate" : "") + ")");
  for (auto& [name, vertices] : groups) {
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    if (!vertices.empty()) out.groups.push_back({name, std::move(vertices)});
  }

  const MeshTopology topo = mesh_topology(out.mesh);
  // The messages name an example edge, which exists only when the test fails (the edge is
  // {-1, -1} otherwise): they are built only then.
  const auto at = [&](int v) { return "(" + to_text(out.mesh.vertices[v].transpose()) + ")"; };
  if (topo.non_manifold_edges != 0) {
    throw InputError(field, value,
                     "a manifold mesh: each edge shared by at most two triangles (" +
                         std::to_string(topo.non_manifold_edges) +
                         " edges are shared by more, e.g. " + at(topo.first_non_manifold_edge[0]) +
                         "-" + at(topo.first_non_manifold_edge[1]) + ")");
  }
  if (topo.misoriented_edges != 0) {
    throw InputError(
        field, value,
        "a consistently oriented mesh: neighbouring triangles run through their shared edge "
        "in opposite directions (" +
            std::to_string(topo.misoriented_edges) + " edges do not, e.g. " +
            at(topo.first_misoriented_edge[0]) + "-" + at(topo.first_misoriented_edge[1]) + ")");
  }
  return out;
}

void require_small_holes(const MeshTopology& topology, Real max_hole_diameter,
                         const std::string& field, const std::string& file,
                         const std::string& what_fills) {
  if (topology.holes.empty()) return;
  const MeshHole& worst = topology.holes.front();  // sorted by diameter, largest first
  require(worst.diameter <= max_hole_diameter, field, quoted(file),
          "a closed mesh, or one whose holes are at most " + to_text(max_hole_diameter) +
              " across (" + what_fills + "); it has " + std::to_string(topology.holes.size()) +
              " hole(s), the largest " + to_text(worst.diameter) + " across at (" +
              to_text(worst.centre.transpose()) + ")");
}

void write_mesh(const std::string& path, const TriangleMesh& mesh) {
  const std::string ext = lower_extension(path);
  require(ext == ".obj" || ext == ".stl" || ext == ".ply", "mesh file", quoted(path),
          "a file ending in .obj, .stl or .ply");
  std::ofstream out(path, std::ios::binary);
  require(static_cast<bool>(out), "mesh file", quoted(path), "a file that can be written");
  out.precision(17);
  if (ext == ".obj") {
    for (const Vec3& v : mesh.vertices)
      out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    for (const Triangle& t : mesh.triangles) {
      out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }
  } else if (ext == ".ply") {
    out << "ply\nformat ascii 1.0\nelement vertex " << mesh.num_vertices()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face "
        << mesh.num_triangles() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const Vec3& v : mesh.vertices) out << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    for (const Triangle& t : mesh.triangles)
      out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  } else {
    // Binary STL: 80-byte header, count, then per triangle normal, 3 vertices (float32) and a
    // 2-byte attribute.
    char header[80] = "binary STL written by jelly";
    out.write(header, sizeof header);
    const auto count = static_cast<std::uint32_t>(mesh.num_triangles());
    out.write(reinterpret_cast<const char*>(&count), 4);
    for (const Triangle& t : mesh.triangles) {
      const Vec3& a = mesh.vertices[t[0]];
      const Vec3& b = mesh.vertices[t[1]];
      const Vec3& c = mesh.vertices[t[2]];
      const Vec3 n = (b - a).cross(c - a).normalized();
      float data[12];
      for (int k = 0; k < 3; ++k) {
        data[k] = static_cast<float>(n[k]);
        data[3 + k] = static_cast<float>(a[k]);
        data[6 + k] = static_cast<float>(b[k]);
        data[9 + k] = static_cast<float>(c[k]);
      }
      out.write(reinterpret_cast<const char*>(data), sizeof data);
      const std::uint16_t attribute = 0;
      out.write(reinterpret_cast<const char*>(&attribute), 2);
    }
  }
  require(static_cast<bool>(out.flush()), "mesh file", quoted(path), "a file that can be written");
}

}  // namespace jelly
