#include <jelly/terrain/elevator.hpp>

#include <cmath>

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
  spec_.validate();
  contact.validate("contact.");
}

bool Elevator::can_contact(const Vec3& p, Real t) const {
  const Real d = signed_distance(p, t);
  return std::abs(p.x() - spec_.center.x()) <= 0.5 * spec_.size_x &&
         std::abs(p.z() - spec_.center.z()) <= 0.5 * spec_.size_z && d > -spec_.thickness;
}

}  // namespace jelly
