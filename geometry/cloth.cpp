#include <jelly/geometry/detail/cloth.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

void ClothShape::validate(const std::string& prefix) const {
  require(nu >= 2 && nu <= 10000, prefix + "nu", nu, "an integer in [2, 10000]");
  require(nv >= 2 && nv <= 10000, prefix + "nv", nv, "an integer in [2, 10000]");
  require(std::isfinite(size_u) && size_u > 0, prefix + "size_u", size_u, "a finite size > 0 (m)");
  require(std::isfinite(size_v) && size_v > 0, prefix + "size_v", size_v, "a finite size > 0 (m)");
  pose.validate(prefix);
  require(pose.scale == 1, prefix + "scale", pose.scale, "1 (give the sizes instead)");
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

void ClothShape::write(Json& j) const {
  j["nu"] = nu;
  j["nv"] = nv;
  j["size_u"] = size_u;
  j["size_v"] = size_v;
  j["position"] = json_of(pose.position);
  j["rotation_degrees"] = json_of(pose.rotation_degrees);
}

std::unique_ptr<BodyShape> ClothShape::read(JsonFields& f) {
  auto s = std::make_unique<ClothShape>();
  s->nu = f.integer_or("nu", s->nu);
  s->nv = f.integer_or("nv", s->nv);
  s->size_u = f.number_or("size_u", s->size_u);
  s->size_v = f.number_or("size_v", s->size_v);
  s->pose.position = f.vec3_or("position", s->pose.position);
  s->pose.rotation_degrees = f.vec3_or("rotation_degrees", s->pose.rotation_degrees);
  s->validate(f.prefix());
  return s;
}

}  // namespace jelly
