#include <jelly/geometry/detail/tetmesh.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>

namespace jelly {

namespace {

using detail::quoted;

// Six times the signed volume of tet (a, b, c, d).
Real six_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a));
}

}  // namespace

void validate_tet_mesh(const TetMesh& mesh, const std::string& field, const std::string& file) {
  const std::string value = quoted(file);
  require(mesh.num_tets() > 0, field, value, "a mesh with at least one tetrahedron (it has none)");
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    // (The messages are built only on failure: these loops are hot.)
    if (!mesh.vertices[v].allFinite()) {
      throw InputError(field, value,
                       "a mesh with finite coordinates (vertex " + std::to_string(v) + " is at (" +
                           to_text(mesh.vertices[v].transpose()) + "))");
    }
  }
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& tet = mesh.tets[t];
    for (int c : tet) {
      if (c < 0 || c >= mesh.num_vertices()) {
        throw InputError(field, value,
                         "a mesh whose tetrahedra name its vertices (tet " + std::to_string(t) +
                             " names vertex " + std::to_string(c) + " of " +
                             std::to_string(mesh.num_vertices()) + ")");
      }
    }
    const Vec3& a = mesh.vertices[tet[0]];
    const Vec3& b = mesh.vertices[tet[1]];
    const Vec3& c = mesh.vertices[tet[2]];
    const Vec3& d = mesh.vertices[tet[3]];
    const Real longest = std::max({(a - b).norm(), (a - c).norm(), (a - d).norm(), (b - c).norm(),
                                   (b - d).norm(), (c - d).norm()});
    if (!(std::abs(six_volume(a, b, c, d)) > 6e-12 * longest * longest * longest)) {
      throw InputError(
          field, value,
          "a mesh of tetrahedra with a volume (tet " + std::to_string(t) + " is flat)");
    }
  }
  // Each tet once: the tets sorted by their sorted corners, neighbours compared.
  std::vector<std::pair<Tet, int>> sorted(mesh.tets.size());
  for (int t = 0; t < mesh.num_tets(); ++t) {
    sorted[t] = {mesh.tets[t], t};
    std::sort(sorted[t].first.begin(), sorted[t].first.end());
  }
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    if (sorted[i].first == sorted[i - 1].first) {
      throw InputError(field, value,
                       "a mesh in which each tetrahedron appears once (tets " +
                           std::to_string(sorted[i - 1].second) + " and " +
                           std::to_string(sorted[i].second) + " have the same vertices)");
    }
  }
}

void drop_unused_vertices(TetMesh& mesh) {
  std::vector<int> index(mesh.vertices.size(), -1);
  for (const Tet& t : mesh.tets) {
    for (int c : t) {
      if (c >= 0 && c < mesh.num_vertices()) index[c] = 0;
    }
  }
  int next = 0;
  std::vector<Vec3> kept;
  for (std::size_t v = 0; v < index.size(); ++v) {
    if (index[v] == 0) {
      index[v] = next++;
      kept.push_back(mesh.vertices[v]);
    }
  }
  if (next == mesh.num_vertices()) return;
  for (Tet& t : mesh.tets) {
    for (int& c : t) c = (c >= 0 && c < static_cast<int>(index.size())) ? index[c] : -1;
  }
  for (VertexGroup& g : mesh.groups) {
    std::vector<int> vs;
    for (int v : g.vertices) {
      if (v >= 0 && v < static_cast<int>(index.size()) && index[v] >= 0) vs.push_back(index[v]);
    }
    g.vertices = std::move(vs);
  }
  mesh.groups.erase(std::remove_if(mesh.groups.begin(), mesh.groups.end(),
                                   [](const VertexGroup& g) { return g.vertices.empty(); }),
                    mesh.groups.end());
  mesh.vertices = std::move(kept);
}

std::vector<std::array<int, 2>> tet_edges(const std::vector<Tet>& tets) {
  // Each tet's 6 edges as 64-bit keys min * 2^32 + max; sorted and made unique.
  std::vector<std::uint64_t> keys;
  keys.reserve(6 * tets.size());
  constexpr int kPairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (const Tet& t : tets) {
    for (const auto& p : kPairs) {
      const auto a = static_cast<std::uint32_t>(t[p[0]]), b = static_cast<std::uint32_t>(t[p[1]]);
      keys.push_back(a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a));
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<std::array<int, 2>> edges(keys.size());
  for (std::size_t e = 0; e < keys.size(); ++e) {
    edges[e] = {static_cast<int>(keys[e] >> 32), static_cast<int>(keys[e] & 0xffffffffu)};
  }
  return edges;
}

std::vector<Triangle> tet_boundary(const std::vector<Tet>& tets,
                                   const std::vector<Vec3>& vertices) {
  // Each face once per tet, by its sorted corners, with the tet's vertex opposite it.
  struct Face {
    std::array<int, 3> sorted;
    Triangle corners;
    int opposite;
  };
  std::vector<Face> faces;
  faces.reserve(4 * tets.size());
  for (const Tet& t : tets) {
    for (int skip = 0; skip < 4; ++skip) {
      Face f;
      int k = 0;
      for (int c = 0; c < 4; ++c) {
        if (c != skip) f.corners[k++] = t[c];
      }
      f.sorted = f.corners;
      std::sort(f.sorted.begin(), f.sorted.end());
      f.opposite = t[skip];
      faces.push_back(f);
    }
  }
  std::sort(faces.begin(), faces.end(),
            [](const Face& x, const Face& y) { return x.sorted < y.sorted; });
  std::vector<Triangle> boundary;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].sorted == faces[i].sorted) ++j;
    if (j - i == 1) {
      Triangle t = faces[i].corners;
      const Vec3& a = vertices[t[0]];
      const Vec3 n = (vertices[t[1]] - a).cross(vertices[t[2]] - a);
      if (n.dot(vertices[faces[i].opposite] - a) > 0) std::swap(t[1], t[2]);
      boundary.push_back(t);
    }
    i = j;
  }
  return boundary;
}

BodyPart build_tetmesh(const TetMesh& mesh, const Pose& pose, const Material& material,
                       const std::string& prefix) {
  pose.validate(prefix);
  validate_tet_mesh(mesh, prefix + "file", "the mesh");
  BodyPart part;
  part.kind = "tetmesh";
  const int n = mesh.num_vertices();
  part.position.resize(3 * n);
  const Eigen::Matrix3d r = pose.rotation();
  for (int v = 0; v < n; ++v) {
    particle(part.position, v) = pose.position + pose.scale * (r * mesh.vertices[v]);
  }
  // Lumped masses: a quarter of each tet's mass to each of its corners.
  if (material.density > 0) {
    part.mass = VecX::Zero(n);
    for (const Tet& t : mesh.tets) {
      const Real volume =
          std::abs(six_volume(particle(part.position, t[0]), particle(part.position, t[1]),
                              particle(part.position, t[2]), particle(part.position, t[3]))) /
          6;
      for (int c : t) part.mass[c] += material.density * volume / 4;
    }
  } else {
    part.mass = VecX::Constant(n, material.particle_mass);
  }
  // A vertex without a tet would have no mass and no spring: the readers drop them; one given
  // in code is an error.
  std::vector<char> used(n, 0);
  for (const Tet& t : mesh.tets) {
    for (int c : t) used[c] = 1;
  }
  for (int v = 0; v < n; ++v) {
    if (used[v] == 0) {
      throw InputError(prefix + "file", "the mesh",
                       "a mesh whose every vertex belongs to a tetrahedron (vertex " +
                           std::to_string(v) + " belongs to none)");
    }
  }
  const std::vector<std::array<int, 2>> edges = tet_edges(mesh.tets);
  std::vector<Real> lengths;
  lengths.reserve(edges.size());
  const SpringCoefficients c = material.springs[static_cast<int>(SpringType::kStructural)];
  for (const auto& e : edges) {
    const Real rest = (particle(part.position, e[0]) - particle(part.position, e[1])).norm();
    part.springs.add(e[0], e[1], rest, c, SpringType::kStructural);
    lengths.push_back(rest);
  }
  // The median edge length as the typical spacing (the default contact radius is half of it).
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  part.spacing = lengths[lengths.size() / 2];

  // The boundary triangles over the boundary vertices only.
  std::vector<Vec3> placed(n);
  for (int v = 0; v < n; ++v) placed[v] = particle(part.position, v);
  std::vector<int> vertex_of(n, -1);
  for (Triangle t : tet_boundary(mesh.tets, placed)) {
    for (int& corner : t) {
      if (vertex_of[corner] < 0) {
        vertex_of[corner] = part.surface.num_vertices();
        part.surface.add_particle_vertex(corner);
      }
      corner = vertex_of[corner];
    }
    part.surface.triangles.push_back(t);
  }
  for (const VertexGroup& g : mesh.groups) part.groups.push_back({g.name, g.vertices});
  part.volume.tets.reserve(mesh.tets.size());
  for (const Tet& t : mesh.tets) {
    std::array<int, 4> oriented{t[0], t[1], t[2], t[3]};
    if (six_volume(placed[t[0]], placed[t[1]], placed[t[2]], placed[t[3]]) < 0)
      std::swap(oriented[2], oriented[3]);
    part.volume.tets.push_back(oriented);
  }
  return part;
}

struct TetmeshShape::Cache {
  std::string file;
  TetMesh mesh;
  long edges = 0;  // tet_edges(mesh.tets).size(): the springs build() makes
};

const TetMesh& TetmeshShape::mesh(const std::string& prefix) const {
  std::shared_ptr<const Cache> cache = std::atomic_load(&cache_);
  if (!cache || cache->file != file) {
    auto fresh = std::make_shared<Cache>();
    fresh->file = file;
    fresh->mesh = read_tet_mesh(file, prefix + "file");
    fresh->edges = static_cast<long>(tet_edges(fresh->mesh.tets).size());
    cache = fresh;
    std::atomic_store(&cache_, cache);
  }
  return cache->mesh;
}

const FieldTable<TetmeshShape>& tetmesh_shape_fields() {
  using T = TetmeshShape;
  static const FieldTable<T> table{
      "TetmeshShape",
      "bodies[i]",
      "Springs along the edges of a tetrahedral mesh",
      {
          file_field<&T::file>("file", "the name of a .msh, .node or .ele file",
                               "The tet mesh (Gmsh .msh, TetGen .node/.ele)"),
          pose_scale_field<&T::pose, &Pose::scale>(),
          pose_position_field<&T::pose, &Pose::position>("Where the mesh's origin goes"),
          pose_rotation_field<&T::pose, &Pose::rotation_degrees>(),
      },
      // The mesh itself: read and checked.
      [](const T& s, const std::string& prefix) { s.mesh(prefix); },
  };
  return table;
}

void TetmeshShape::validate(const std::string& prefix) const {
  validate_fields(tetmesh_shape_fields(), *this, prefix);
}

BodyPart TetmeshShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  return build_tetmesh(mesh(prefix), pose, material, prefix);
}

long TetmeshShape::estimated_particles() const { return mesh().num_vertices(); }

long TetmeshShape::estimated_springs() const {
  mesh();  // reads the file and counts its edges on first use
  return std::atomic_load(&cache_)->edges;
}

void TetmeshShape::write(Json& j) const { write_fields(tetmesh_shape_fields(), *this, j); }

std::unique_ptr<BodyShape> TetmeshShape::read(JsonFields& f) {
  auto s = std::make_unique<TetmeshShape>();
  read_fields(tetmesh_shape_fields(), f, *s, f.prefix());
  return s;
}

}  // namespace jelly
