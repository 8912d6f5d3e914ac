#include <jelly/geometry/detail/box.hpp>

#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

void BoxShape::validate(const std::string& prefix) const {
  const char* axes[3] = {"nx", "ny", "nz"};
  for (int a = 0; a < 3; ++a) {
    require(n[a] >= 2 && n[a] <= 2000, prefix + axes[a], n[a], "an integer in [2, 2000]");
  }
  require(size.allFinite() && size.minCoeff() > 0, prefix + "size", size.transpose(),
          "three finite sizes > 0 (m)");
  pose.validate(prefix);
  require(pose.scale == 1, prefix + "scale", pose.scale, "1 (give the size instead)");
}

BodyPart BoxShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  LatticeGrid grid;
  grid.n = n;
  for (int a = 0; a < 3; ++a) grid.spacing[a] = size[a] / (n[a] - 1);
  grid.rotation = pose.rotation();
  grid.origin = pose.position - grid.rotation * (0.5 * size);
  return build_lattice(grid, material, "box");
}

void BoxShape::write(Json& j) const {
  j["nx"] = n[0];
  j["ny"] = n[1];
  j["nz"] = n[2];
  j["size"] = json_of(size);
  j["position"] = json_of(pose.position);
  j["rotation_degrees"] = json_of(pose.rotation_degrees);
}

std::unique_ptr<BodyShape> BoxShape::read(JsonFields& f) {
  auto s = std::make_unique<BoxShape>();
  s->n[0] = f.integer_or("nx", s->n[0]);
  s->n[1] = f.integer_or("ny", s->n[1]);
  s->n[2] = f.integer_or("nz", s->n[2]);
  s->size = f.vec3_or("size", s->size);
  s->pose.position = f.vec3_or("position", s->pose.position);
  s->pose.rotation_degrees = f.vec3_or("rotation_degrees", s->pose.rotation_degrees);
  s->validate(f.prefix());
  return s;
}

}  // namespace jelly
