#include <jelly/terrain/plane.hpp>

#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/terrain_fields.hpp>

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

Real Plane::signed_distance(const Vec3& p, Real /*t*/) const { return normal_.dot(p - point_); }

Vec3 Plane::surface_velocity(const Vec3& /*p*/, Real /*t*/) const { return Vec3::Zero(); }

TriangleMesh Plane::render_mesh() const { return square_mesh(normal_, kRenderSize); }

const FieldTable<PlaneSpec>& plane_fields() {
  using P = PlaneSpec;
  static const FieldTable<P> table{
      "PlaneSpec",
      "terrains[i]",
      "A fixed plane through `point` with outward `normal`",
      {
          vec3_field<&P::point>("point", "m", range_finite(), "finite coordinates",
                                "A point of the plane"),
          vec3_field<&P::normal>("normal", "", range_above(1e-12), "a finite, non-zero vector",
                                 "The outward normal (any length but zero)"),
      },
  };
  return table;
}

void PlaneSpec::validate(const std::string& prefix) const {
  validate_fields(plane_fields(), *this, prefix);
}

std::unique_ptr<Terrain> PlaneSpec::make() const {
  return std::make_unique<Plane>(point, normal, contact);
}

void PlaneSpec::write(Json& object) const { write_fields(plane_fields(), *this, object); }

std::unique_ptr<TerrainSpec> PlaneSpec::read(JsonFields& f) {
  auto spec = std::make_unique<PlaneSpec>();
  read_fields(plane_fields(), f, *spec, f.prefix());
  return spec;
}

const FieldTable<SlopeSpec>& slope_fields() {
  using S = SlopeSpec;
  static const FieldTable<S> table{
      "SlopeSpec",
      "terrains[i]",
      "A plane through `point` tilted by `angle_degrees` about z: normal (sin a, cos a, 0)",
      {
          number_field<&S::angle_degrees>("angle_degrees", "degrees", range_open(-90, 90),
                                          "an angle in (-90, 90) degrees",
                                          "The tilt about the z axis"),
          vec3_field<&S::point>("point", "m", range_finite(), "finite coordinates",
                                "A point of the plane"),
      },
  };
  return table;
}

void SlopeSpec::validate(const std::string& prefix) const {
  validate_fields(slope_fields(), *this, prefix);
}

std::unique_ptr<Terrain> SlopeSpec::make() const {
  return std::make_unique<Plane>(Plane::slope(angle_degrees, point, contact));
}

void SlopeSpec::write(Json& object) const { write_fields(slope_fields(), *this, object); }

std::unique_ptr<TerrainSpec> SlopeSpec::read(JsonFields& f) {
  auto spec = std::make_unique<SlopeSpec>();
  read_fields(slope_fields(), f, *spec, f.prefix());
  return spec;
}

}  // namespace jelly
