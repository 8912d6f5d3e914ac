#include <jelly/terrain/plane.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

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

TriangleMesh Plane::render_mesh() const { return square_mesh(normal_, kRenderSize); }

void PlaneSpec::validate(const std::string& prefix) const {
  require(point.allFinite(), prefix + "point", point.transpose(), "finite coordinates");
  require(normal.allFinite() && normal.norm() > 1e-12, prefix + "normal", normal.transpose(),
          "a finite, non-zero vector");
}

std::unique_ptr<Terrain> PlaneSpec::make() const {
  return std::make_unique<Plane>(point, normal, contact);
}

void PlaneSpec::write(Json& object) const {
  object["point"] = json_of(point);
  object["normal"] = json_of(normal);
}

std::unique_ptr<TerrainSpec> PlaneSpec::read(JsonFields& f) {
  auto spec = std::make_unique<PlaneSpec>();
  spec->point = f.vec3_or("point", spec->point);
  spec->normal = f.vec3_or("normal", spec->normal);
  spec->validate(f.prefix());
  return spec;
}

void SlopeSpec::validate(const std::string& prefix) const {
  require(std::isfinite(angle_degrees) && std::abs(angle_degrees) < 90, prefix + "angle_degrees",
          angle_degrees, "an angle in (-90, 90) degrees");
  require(point.allFinite(), prefix + "point", point.transpose(), "finite coordinates");
}

std::unique_ptr<Terrain> SlopeSpec::make() const {
  return std::make_unique<Plane>(Plane::slope(angle_degrees, point, contact));
}

void SlopeSpec::write(Json& object) const {
  object["angle_degrees"] = angle_degrees;
  object["point"] = json_of(point);
}

std::unique_ptr<TerrainSpec> SlopeSpec::read(JsonFields& f) {
  auto spec = std::make_unique<SlopeSpec>();
  spec->angle_degrees = f.number_or("angle_degrees", spec->angle_degrees);
  spec->point = f.vec3_or("point", spec->point);
  spec->validate(f.prefix());
  return spec;
}

}  // namespace jelly
