#include <jelly/geometry/detail/cloth.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

namespace jelly {

const FieldTable<ClothShape>& cloth_shape_fields() {
  using C = ClothShape;
  static const FieldTable<C> table{
      "ClothShape",
      "bodies[i]",
      "A sheet of nu x nv particles in its own x-z plane (u along x, v along z)",
      {
          integer_field<&C::nu>("nu", "", range_closed(2, 10000), "an integer in [2, 10000]",
                                "Particles along u"),
          integer_field<&C::nv>("nv", "", range_closed(2, 10000), "an integer in [2, 10000]",
                                "Particles along v"),
          number_field<&C::size_u>("size_u", "m", range_above(0), "a finite size > 0 (m)",
                                   "Length along u"),
          number_field<&C::size_v>("size_v", "m", range_above(0), "a finite size > 0 (m)",
                                   "Length along v"),
          pose_position_field<&C::pose, &Pose::position>("Where the sheet's centre is"),
          pose_rotation_field<&C::pose, &Pose::rotation_degrees>(),
      },
      // The pose's scale is no key of a cloth (its sizes are): only code can set it.
      [](const C& s, const std::string& prefix) {
        require(s.pose.scale == 1, prefix + "scale", s.pose.scale, "1 (give the sizes instead)");
      },
  };
  return table;
}

void ClothShape::validate(const std::string& prefix) const {
  validate_fields(cloth_shape_fields(), *this, prefix);
}

BodyPart ClothShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  const Real du = size_u / (nu - 1), dv = size_v / (nv - 1);
  const Eigen::Matrix3d r = pose.rotation();
  const auto index = [&](int i, int j) { return i * nv + j; };
  BodyPart part;
  part.kind = "cloth";
  part.sheet = true;
  part.spacing = std::min(du, dv);
  part.mass.resize(nu * nv);
  part.position.resize(3 * nu * nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Vec3 local(i * du - 0.5 * size_u, 0, j * dv - 0.5 * size_v);
      particle(part.position, index(i, j)) = pose.position + r * local;
      if (material.density > 0) {
        // The particle's share of the sheet's area.
        const Real wu = (i == 0 || i == nu - 1) ? 0.5 : 1.0;
        const Real wv = (j == 0 || j == nv - 1) ? 0.5 : 1.0;
        part.mass[index(i, j)] = material.density * wu * du * wv * dv;
      } else {
        part.mass[index(i, j)] = material.particle_mass;
      }
    }
  const auto connect = [&](int i, int j, int di, int dj, SpringType type) {
    if (i + di < 0 || i + di >= nu || j + dj < 0 || j + dj >= nv) return;
    const int a = index(i, j), b = index(i + di, j + dj);
    const Real rest = (particle(part.position, a) - particle(part.position, b)).norm();
    part.springs.add(a, b, rest, material.springs[static_cast<int>(type)], type);
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      connect(i, j, 1, 0, SpringType::kStructural);
      connect(i, j, 0, 1, SpringType::kStructural);
      connect(i, j, 1, 1, SpringType::kShear);
      connect(i, j, 1, -1, SpringType::kShear);
      connect(i, j, 2, 0, SpringType::kBending);
      connect(i, j, 0, 2, SpringType::kBending);
    }
  // The sheet's quads, counter-clockwise seen from its +y side (local u x v = -y, so v then u).
  for (int p = 0; p < nu * nv; ++p) part.surface.add_particle_vertex(p);
  for (int i = 0; i + 1 < nu; ++i)
    for (int j = 0; j + 1 < nv; ++j) {
      const int a = index(i, j), b = index(i, j + 1), c = index(i + 1, j + 1), d = index(i + 1, j);
      part.surface.triangles.push_back({a, b, c});
      part.surface.triangles.push_back({a, c, d});
    }
  // Named corners for pins.
  part.groups = {{"corner_00", {index(0, 0)}},
                 {"corner_10", {index(nu - 1, 0)}},
                 {"corner_01", {index(0, nv - 1)}},
                 {"corner_11", {index(nu - 1, nv - 1)}},
                 {"edge_v0", {}},
                 {"edge_v1", {}}};
  for (int i = 0; i < nu; ++i) {
    part.groups[4].particles.push_back(index(i, 0));
    part.groups[5].particles.push_back(index(i, nv - 1));
  }
  return part;
}

long ClothShape::estimated_springs() const {
  const long u = nu, v = nv;
  const long structural = (u - 1) * v + u * (v - 1);
  const long shear = 2 * (u - 1) * (v - 1);
  const long bending = std::max(u - 2, 0L) * v + u * std::max(v - 2, 0L);
  return structural + shear + bending;
}

void ClothShape::write(Json& j) const { write_fields(cloth_shape_fields(), *this, j); }

std::unique_ptr<BodyShape> ClothShape::read(JsonFields& f) {
  auto s = std::make_unique<ClothShape>();
  read_fields(cloth_shape_fields(), f, *s, f.prefix());
  return s;
}

}  // namespace jelly
