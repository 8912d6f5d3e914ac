#include <jelly/geometry/detail/voxelized.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <deque>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>
#include <jelly/geometry/detail/winding_number.hpp>

namespace jelly {

namespace {

// A lattice point this close to the mesh (in spacings) is on it, and inside.
constexpr Real kOnSurface = 1e-9;

// Six times the signed volume the triangles enclose (> 0 when they face outwards).
Real six_volume(const TriangleMesh& mesh) {
  Real sum = 0;
  for (const Triangle& t : mesh.triangles) {
    sum += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return sum;
}

// The mesh placed by the pose, turned outwards when it faces inwards.
TriangleMesh placed_outwards(const TriangleMesh& mesh, const Pose& pose, bool scale_only) {
  TriangleMesh out;
  out.vertices.reserve(mesh.vertices.size());
  if (scale_only) {
    for (const Vec3& v : mesh.vertices) out.vertices.push_back(pose.scale * v);
  } else {
    const Eigen::Matrix3d r = pose.rotation();
    for (const Vec3& v : mesh.vertices)
      out.vertices.push_back(pose.position + pose.scale * (r * v));
  }
  out.triangles = mesh.triangles;
  if (six_volume(mesh) < 0) {
    for (Triangle& t : out.triangles) std::swap(t[1], t[2]);
  }
  return out;
}

int points_along(Real extent, Real spacing) {
  return static_cast<int>(std::floor(extent / spacing + kOnSurface)) + 1;
}

}  // namespace

long voxel_grid_points(const Eigen::AlignedBox3d& bounds, Real spacing, Real scale) {
  if (bounds.isEmpty()) return 0;
  double points = 1;
  for (int a = 0; a < 3; ++a) {
    points *= std::floor(scale * bounds.diagonal()[a] / spacing + kOnSurface) + 1;
  }
  return points >= static_cast<double>(LONG_MAX / 2) ? LONG_MAX / 2 : static_cast<long>(points);
}

LatticeGrid voxelize(const TriangleMesh& mesh, Real spacing, const Pose& pose) {
  // The lattice is laid out in the mesh's scaled frame, then turned and moved by the pose.
  const TriangleMesh local = placed_outwards(mesh, pose, /*scale_only=*/true);
  const Eigen::AlignedBox3d box = local.bounds();
  LatticeGrid grid;
  Vec3 corner;
  for (int a = 0; a < 3; ++a) {
    grid.n[a] = points_along(box.diagonal()[a], spacing);
    corner[a] = box.center()[a] - 0.5 * (grid.n[a] - 1) * spacing;
  }
  grid.spacing = Vec3::Constant(spacing);
  grid.rotation = pose.rotation();
  grid.origin = pose.position + grid.rotation * corner;

  const WindingNumber winding(local);
  grid.occupied.assign(grid.points(), 0);
  for (int i = 0; i < grid.n[0]; ++i)
    for (int j = 0; j < grid.n[1]; ++j)
      for (int k = 0; k < grid.n[2]; ++k) {
        const Vec3 p = corner + spacing * Vec3(i, j, k);
        grid.occupied[grid.index(i, j, k)] =
            winding(p) >= 0.5 || winding.near_surface(p, kOnSurface * spacing);
      }
  return grid;
}

Surface embed_in_lattice(const LatticeGrid& grid, const TriangleMesh& mesh, const Pose& pose,
                         const std::string& field) {
  const TriangleMesh placed = placed_outwards(mesh, pose, /*scale_only=*/false);
  const std::vector<int> index = lattice_particle_indices(grid);
  const std::array<int, 3> cells{grid.n[0] - 1, grid.n[1] - 1, grid.n[2] - 1};
  const auto cell_index = [&](int i, int j, int k) { return (i * cells[1] + j) * cells[2] + k; };
  std::vector<char> solid(static_cast<std::size_t>(cells[0]) * cells[1] * cells[2], 0);
  bool any_solid = false;
  for (int i = 0; i < cells[0]; ++i)
    for (int j = 0; j < cells[1]; ++j)
      for (int k = 0; k < cells[2]; ++k) {
        bool full = true;
        for (int c = 0; c < 8 && full; ++c) {
          full = grid.is_occupied(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
        }
        solid[cell_index(i, j, k)] = full;
        any_solid = any_solid || full;
      }
  require(any_solid, field, grid.spacing.minCoeff(),
          "a spacing that leaves at least one lattice cell fully inside the mesh (the surface "
          "is embedded in such cells)");

  // For each cell, a fully occupied cell near it: breadth-first over the 26 neighbours from all
  // fully occupied cells at once (filled on first need).
  std::vector<int> nearest;
  const auto fill_nearest = [&] {
    nearest.assign(solid.size(), -1);
    std::deque<int> queue;
    for (std::size_t c = 0; c < solid.size(); ++c) {
      if (solid[c]) {
        nearest[c] = static_cast<int>(c);
        queue.push_back(static_cast<int>(c));
      }
    }
    while (!queue.empty()) {
      const int c = queue.front();
      queue.pop_front();
      const int i = c / (cells[1] * cells[2]), j = (c / cells[2]) % cells[1], k = c % cells[2];
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj)
          for (int dk = -1; dk <= 1; ++dk) {
            const int a = i + di, b = j + dj, e = k + dk;
            if (a < 0 || b < 0 || e < 0 || a >= cells[0] || b >= cells[1] || e >= cells[2])
              continue;
            const int n = cell_index(a, b, e);
            if (nearest[n] >= 0) continue;
            nearest[n] = nearest[c];
            queue.push_back(n);
          }
    }
  };

  const Eigen::Matrix3d rt = grid.rotation.transpose();
  Surface surface;
  surface.triangles = placed.triangles;
  for (const Vec3& x : placed.vertices) {
    // The vertex in grid units: u = R^T (x - origin) / spacing, per axis.
    const Vec3 u = (rt * (x - grid.origin)).cwiseQuotient(grid.spacing);
    std::array<int, 3> cell;
    for (int a = 0; a < 3; ++a) {
      cell[a] = std::clamp(static_cast<int>(std::floor(u[a])), 0, cells[a] - 1);
    }
    if (!solid[cell_index(cell[0], cell[1], cell[2])]) {
      if (nearest.empty()) fill_nearest();
      const int found = nearest[cell_index(cell[0], cell[1], cell[2])];
      const int fi = found / (cells[1] * cells[2]), fj = (found / cells[2]) % cells[1],
                fk = found % cells[2];
      // The closest to the vertex among the fully occupied cells around the one found.
      Real best = std::numeric_limits<Real>::infinity();
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj)
          for (int dk = -1; dk <= 1; ++dk) {
            const std::array<int, 3> c{fi + di, fj + dj, fk + dk};
            if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= cells[0] || c[1] >= cells[1] ||
                c[2] >= cells[2] || !solid[cell_index(c[0], c[1], c[2])]) {
              continue;
            }
            Real d2 = 0;
            for (int a = 0; a < 3; ++a) {
              const Real out = std::max({c[a] - u[a], u[a] - (c[a] + 1), Real(0)});
              d2 += out * out * grid.spacing[a] * grid.spacing[a];
            }
            if (d2 < best) {
              best = d2;
              cell = c;
            }
          }
    }
    // Trilinear weights of the cell's corners at t = u - cell (extrapolated outside [0, 1]).
    const Vec3 t = u - Vec3(cell[0], cell[1], cell[2]);
    int particles[8];
    Real weights[8];
    int count = 0;
    for (int c = 0; c < 8; ++c) {
      const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
      const Real w = (di ? t[0] : 1 - t[0]) * (dj ? t[1] : 1 - t[1]) * (dk ? t[2] : 1 - t[2]);
      if (w == 0) continue;
      particles[count] = index[grid.index(cell[0] + di, cell[1] + dj, cell[2] + dk)];
      weights[count] = w;
      ++count;
    }
    surface.add_vertex(particles, weights, count);
  }
  return surface;
}

BodyPart build_voxelized(const TriangleMesh& mesh, const std::vector<VertexGroup>& groups,
                         Real spacing, const Pose& pose, const Material& material,
                         const std::string& prefix) {
  require(std::isfinite(spacing) && spacing > 0, prefix + "spacing", spacing,
          "a finite spacing > 0 (m)");
  pose.validate(prefix);
  require(mesh.num_triangles() > 0, prefix + "file", "a mesh with no triangle",
          "a mesh with at least one triangle");
  const LatticeGrid grid = voxelize(mesh, spacing, pose);
  long inside = 0;
  for (char o : grid.occupied) inside += o;
  require(inside >= 8, prefix + "spacing", spacing,
          "a spacing that leaves at least 8 lattice points inside the mesh (this one leaves " +
              std::to_string(inside) + ")");
  BodyPart part = build_lattice(grid, material, "voxelized");
  part.surface = embed_in_lattice(grid, mesh, pose, prefix + "spacing");
  for (const VertexGroup& g : groups) {
    ParticleGroup pg{g.name, {}};
    for (int v : g.vertices) {
      if (v < 0 || v >= part.surface.num_vertices()) continue;
      for (int k = part.surface.offsets[v]; k < part.surface.offsets[v + 1]; ++k) {
        pg.particles.push_back(part.surface.particles[k]);
      }
    }
    std::sort(pg.particles.begin(), pg.particles.end());
    pg.particles.erase(std::unique(pg.particles.begin(), pg.particles.end()), pg.particles.end());
    part.groups.push_back(std::move(pg));
  }
  return part;
}

struct VoxelizedShape::Cache {
  std::string file;
  MeshFile mesh;
  MeshTopology topology;
};

const MeshFile& VoxelizedShape::mesh(const std::string& prefix) const {
  std::shared_ptr<const Cache> cache = std::atomic_load(&cache_);
  if (!cache || cache->file != file) {
    auto fresh = std::make_shared<Cache>();
    fresh->file = file;
    fresh->mesh = read_mesh(file, prefix + "file");
    fresh->topology = mesh_topology(fresh->mesh.mesh);
    cache = fresh;
    std::atomic_store(&cache_, cache);
  }
  return cache->mesh;
}

const FieldTable<VoxelizedShape>& voxelized_shape_fields() {
  using V = VoxelizedShape;
  static const FieldTable<V> table{
      "VoxelizedShape",
      "bodies[i]",
      "A closed triangle mesh filled with the lattice",
      {
          file_field<&V::file>("file", "the name of an OBJ, STL or PLY file",
                               "The closed mesh (OBJ, STL or PLY)"),
          required(number_field<&V::spacing>("spacing", "m", range_above(0),
                                             "a finite spacing > 0 (m)",
                                             "Distance between lattice points (after scale)")),
          pose_scale_field<&V::pose, &Pose::scale>(),
          pose_position_field<&V::pose, &Pose::position>("Where the mesh's origin goes"),
          pose_rotation_field<&V::pose, &Pose::rotation_degrees>(),
      },
      // The mesh itself: read, holes small enough, a lattice of sensible size.
      [](const V& s, const std::string& prefix) { s.validate_mesh(prefix); },
  };
  return table;
}

void VoxelizedShape::validate(const std::string& prefix) const {
  validate_fields(voxelized_shape_fields(), *this, prefix);
}

void VoxelizedShape::validate_mesh(const std::string& prefix) const {
  const MeshFile& m = mesh(prefix);
  require_small_holes(std::atomic_load(&cache_)->topology, kMaxHoleSpacings * spacing / pose.scale,
                      prefix + "file", file,
                      "the winding number fills holes up to " + to_text(kMaxHoleSpacings) +
                          " spacings across; in the mesh's units before scale");
  const long points = voxel_grid_points(m.mesh.bounds(), spacing, pose.scale);
  require(points >= 8, prefix + "spacing", spacing,
          "a spacing that leaves at least 8 lattice points in the mesh's bounding box (this one "
          "leaves " +
              std::to_string(points) + ")");
  require(points <= INT_MAX, prefix + "spacing", spacing,
          "a spacing giving at most 2^31 lattice points over the mesh's bounding box");
}

BodyPart VoxelizedShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  const MeshFile& m = mesh(prefix);
  return build_voxelized(m.mesh, m.groups, spacing, pose, material, prefix);
}

long VoxelizedShape::estimated_particles() const {
  return voxel_grid_points(mesh().mesh.bounds(), spacing, pose.scale);
}

void VoxelizedShape::write(Json& j) const { write_fields(voxelized_shape_fields(), *this, j); }

std::unique_ptr<BodyShape> VoxelizedShape::read(JsonFields& f) {
  auto s = std::make_unique<VoxelizedShape>();
  read_fields(voxelized_shape_fields(), f, *s, f.prefix());
  return s;
}

}  // namespace jelly
