#include <jelly/terrain/plane.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

Plane::Plane(const Vec3& point, const Vec3& normal, ContactParams contact)
    : Terrain(contact), point_(point) {
  contact.validate("contact.");
  require(point.allFinite(), "plane.point", point.transpose(), "finite coordinates");
  require(normal.allFinite() && normal.norm() > 1e-12, "plane.normal", normal.transpose(),
          "a finite, non-zero vector");
  normal_ = normal.normalized();
}

Plane Plane::slope(Real angle_degrees, const Vec3& point, ContactParams contact) {
  require(std::isfinite(angle_degrees) && std::abs(angle_degrees) < 90, "slope.angle_degrees",
          angle_degrees, "an angle in (-90, 90) degrees");
  const Real a = angle_degrees * M_PI / 180.0;
  return Plane(point, Vec3(std::sin(a), std::cos(a), 0), contact);
}

}  // namespace jelly
