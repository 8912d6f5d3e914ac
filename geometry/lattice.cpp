#include <jelly/geometry/body_shape.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

namespace jelly {

const FieldTable<SpringCoefficients>& spring_fields() {
  using C = SpringCoefficients;
  static const FieldTable<C> table{
      "SpringCoefficients",
      "bodies[i].springs.structural",
      "A spring type's coefficients (the same keys under structural, shear and bending)",
      {
          number_field<&C::ks>("ks", "N/m", range_at_least(0), "a finite stiffness >= 0",
                               "Stiffness"),
          number_field<&C::kd>("kd", "N s/m", range_at_least(0), "a finite damping >= 0",
                               "Damping along the spring"),
      },
  };
  return table;
}

const FieldTable<Material>& material_fields() {
  using M = Material;
  static const FieldTable<M> table{
      "Material",
      "bodies[i]",
      "A body's masses (its springs: SpringCoefficients per spring type)",
      {particle_mass_field<&M::particle_mass>(), density_field<&M::density>()},
  };
  return table;
}

void Material::validate(const std::string& prefix) const {
  for (int t = 0; t < kSpringTypeCount; ++t) {
    validate_fields(spring_fields(), springs[t],
                    prefix + "springs." + std::string(spring_type_name(SpringType(t))) + ".");
  }
  validate_fields(material_fields(), *this, prefix);
}

bool LatticeGrid::is_occupied(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return false;
  return occupied.empty() || occupied[index(i, j, k)] != 0;
}

Vec3 LatticeGrid::position(int i, int j, int k) const {
  return origin + rotation * Vec3(i * spacing.x(), j * spacing.y(), k * spacing.z());
}

std::vector<int> lattice_particle_indices(const LatticeGrid& grid) {
  std::vector<int> index(grid.points(), -1);
  int next = 0;
  for (int i = 0; i < grid.n[0]; ++i)
    for (int j = 0; j < grid.n[1]; ++j)
      for (int k = 0; k < grid.n[2]; ++k)
        if (grid.is_occupied(i, j, k)) index[grid.index(i, j, k)] = next++;
  return index;
}

namespace {

struct Offset {
  int di, dj, dk;
  SpringType type;
};

// Each neighbour direction once (the opposite direction is the same spring).
constexpr std::array<Offset, 13> kOffsets{{
    {1, 0, 0, SpringType::kStructural},
    {0, 1, 0, SpringType::kStructural},
    {0, 0, 1, SpringType::kStructural},
    {1, 1, 0, SpringType::kShear},
    {1, -1, 0, SpringType::kShear},
    {1, 0, 1, SpringType::kShear},
    {1, 0, -1, SpringType::kShear},
    {0, 1, 1, SpringType::kShear},
    {0, 1, -1, SpringType::kShear},
    {1, 1, 1, SpringType::kShear},
    {1, 1, -1, SpringType::kShear},
    {1, -1, 1, SpringType::kShear},
    {1, -1, -1, SpringType::kShear},
}};

bool solid_cell(const LatticeGrid& g, int i, int j, int k) {
  for (int c = 0; c < 8; ++c) {
    if (!g.is_occupied(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))) return false;
  }
  return true;
}

// Boundary faces of the solid cells, two triangles each, counter-clockwise seen from outside.
Surface boundary_surface(const LatticeGrid& g, const std::vector<int>& index) {
  Surface surface;
  std::vector<int> vertex_of(index.size(), -1);
  const auto vertex = [&](const std::array<int, 3>& p) {
    const int gi = g.index(p[0], p[1], p[2]);
    if (vertex_of[gi] < 0) {
      vertex_of[gi] = surface.num_vertices();
      surface.add_particle_vertex(index[gi]);
    }
    return vertex_of[gi];
  };
  for (int i = 0; i + 1 < g.n[0]; ++i)
    for (int j = 0; j + 1 < g.n[1]; ++j)
      for (int k = 0; k + 1 < g.n[2]; ++k) {
        if (!solid_cell(g, i, j, k)) continue;
        const std::array<int, 3> cell{i, j, k};
        for (int axis = 0; axis < 3; ++axis)
          for (int side = 0; side < 2; ++side) {
            std::array<int, 3> next = cell;
            next[axis] += side ? 1 : -1;
            if (solid_cell(g, next[0], next[1], next[2])) continue;
            const int b = (axis + 1) % 3, c = (axis + 2) % 3;
            std::array<std::array<int, 3>, 4> quad;
            const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int q = 0; q < 4; ++q) {
              quad[q] = cell;
              quad[q][axis] += side;
              quad[q][b] += uv[q][0];
              quad[q][c] += uv[q][1];
            }
            if (side == 0) std::swap(quad[1], quad[3]);  // the outward normal is -axis
            const int v0 = vertex(quad[0]), v1 = vertex(quad[1]), v2 = vertex(quad[2]),
                      v3 = vertex(quad[3]);
            surface.triangles.push_back({v0, v1, v2});
            surface.triangles.push_back({v0, v2, v3});
          }
      }
  return surface;
}

}  // namespace

BodyPart build_lattice(const LatticeGrid& g, const Material& material, const std::string& kind) {
  const std::vector<int> index = lattice_particle_indices(g);
  int count = 0;
  for (int i : index) count += (i >= 0);
  require(count > 0, kind, count, "at least one particle");

  BodyPart part;
  part.kind = kind;
  part.spacing = g.spacing.minCoeff();
  part.mass.resize(count);
  part.position.resize(3 * count);
  for (int i = 0; i < g.n[0]; ++i)
    for (int j = 0; j < g.n[1]; ++j)
      for (int k = 0; k < g.n[2]; ++k) {
        const int p = index[g.index(i, j, k)];
        if (p < 0) continue;
        particle(part.position, p) = g.position(i, j, k);
        if (material.density > 0) {
          // The particle's share of the lattice's volume: half a spacing towards each occupied
          // neighbour along each axis.
          const std::array<int, 3> at{i, j, k};
          Real volume = 1;
          for (int axis = 0; axis < 3; ++axis) {
            std::array<int, 3> lo = at, hi = at;
            --lo[axis];
            ++hi[axis];
            const int sides =
                g.is_occupied(lo[0], lo[1], lo[2]) + g.is_occupied(hi[0], hi[1], hi[2]);
            volume *= 0.5 * g.spacing[axis] * std::max(sides, 1);
          }
          part.mass[p] = material.density * volume;
        } else {
          part.mass[p] = material.particle_mass;
        }
      }

  const auto connect = [&](int i, int j, int k, int di, int dj, int dk, SpringType type) {
    if (!g.is_occupied(i + di, j + dj, k + dk)) return;
    const int a = index[g.index(i, j, k)];
    const int b = index[g.index(i + di, j + dj, k + dk)];
    const Real rest = (particle(part.position, a) - particle(part.position, b)).norm();
    part.springs.add(a, b, rest, material.springs[static_cast<int>(type)], type);
  };
  for (int i = 0; i < g.n[0]; ++i)
    for (int j = 0; j < g.n[1]; ++j)
      for (int k = 0; k < g.n[2]; ++k) {
        if (!g.is_occupied(i, j, k)) continue;
        for (const Offset& o : kOffsets) connect(i, j, k, o.di, o.dj, o.dk, o.type);
        connect(i, j, k, 2, 0, 0, SpringType::kBending);
        connect(i, j, k, 0, 2, 0, SpringType::kBending);
        connect(i, j, k, 0, 0, 2, SpringType::kBending);
      }
  part.surface = boundary_surface(g, index);
  for (int i = 0; i + 1 < g.n[0]; ++i)
    for (int j = 0; j + 1 < g.n[1]; ++j)
      for (int k = 0; k + 1 < g.n[2]; ++k) {
        if (!solid_cell(g, i, j, k)) continue;
        std::array<int, 8> cell;
        for (int c = 0; c < 8; ++c)
          cell[c] = index[g.index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
        part.volume.cells.push_back(cell);
      }
  return part;
}

}  // namespace jelly
