#include <jelly/terrain/detail/elevator.hpp>

#include <cmath>
#include <limits>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

void ElevatorSpec::validate(const std::string& prefix) const {
  require(center.allFinite(), prefix + "center", center.transpose(), "finite coordinates");
  require(std::isfinite(size_x) && size_x > 0, prefix + "size_x", size_x, "a finite size > 0");
  require(std::isfinite(size_z) && size_z > 0, prefix + "size_z", size_z, "a finite size > 0");
  require(std::isfinite(thickness) && thickness > 0, prefix + "thickness", thickness,
          "a finite thickness > 0");
  require(mass > 0, prefix + "mass", mass, "a mass > 0 (inf for an immovable platform)");
}

Elevator::Elevator(ElevatorSpec spec, ContactParams contact)
    : Terrain(contact), spec_(std::move(spec)) {
  spec_.validate("elevator.");
  contact.validate("contact.");
}

bool Elevator::can_contact(const Vec3& p, Real t) const {
  const Real d = signed_distance(p, t);
  return std::abs(p.x() - spec_.center.x()) <= 0.5 * spec_.size_x &&
         std::abs(p.z() - spec_.center.z()) <= 0.5 * spec_.size_z && d > -spec_.thickness;
}

TriangleMesh Elevator::render_mesh() const {
  TriangleMesh mesh = box_mesh(Vec3(spec_.size_x, spec_.thickness, spec_.size_z));
  for (Vec3& v : mesh.vertices) v.y() -= 0.5 * spec_.thickness;
  return mesh;
}

std::unique_ptr<Terrain> ElevatorSpec::make() const {
  return std::make_unique<Elevator>(*this, contact);
}

namespace {

Real read_mass(const Json& j, const std::string& path) {
  if (j.is_string() && j.get<std::string>() == "inf") return std::numeric_limits<Real>::infinity();
  if (!j.is_number()) throw InputError(path, json_text(j), "a number or \"inf\"");
  return j.get<Real>();
}

}  // namespace

void ElevatorSpec::write(Json& j) const {
  j["center"] = json_of(center);
  j["size_x"] = size_x;
  j["size_z"] = size_z;
  j["thickness"] = thickness;
  j["mass"] = std::isinf(mass) ? Json("inf") : Json(mass);
  j["motion"] = motion.to_json();
}

std::unique_ptr<TerrainSpec> ElevatorSpec::read(JsonFields& f) {
  auto e = std::make_unique<ElevatorSpec>();
  e->center = f.vec3_or("center", e->center);
  e->size_x = f.number_or("size_x", e->size_x);
  e->size_z = f.number_or("size_z", e->size_z);
  e->thickness = f.number_or("thickness", e->thickness);
  if (const Json* m = f.value("mass")) e->mass = read_mass(*m, f.path("mass"));
  if (const Json* m = f.value("motion")) e->motion = ElevatorMotion::read(*m, f.path("motion"));
  e->validate(f.prefix());
  return e;
}

}  // namespace jelly
