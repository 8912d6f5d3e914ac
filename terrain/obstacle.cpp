#include <jelly/terrain/detail/obstacle.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/terrain_fields.hpp>

namespace jelly {

namespace {

Real sign_of(Real x) { return x < 0 ? -1.0 : 1.0; }

// The 2-D rounded-box distance of (a, b) from the rectangle |a| <= ea, |b| <= eb (a, b >= 0 are
// the absolute coordinates), with the weights of its gradient along a and b.
Real rectangle_distance(Real a, Real b, Real ea, Real eb, Real& ga, Real& gb) {
  const Real da = a - ea, db = b - eb;
  if (da > 0 || db > 0) {
    const Real pa = std::max(da, 0.0), pb = std::max(db, 0.0);
    const Real d = std::hypot(pa, pb);
    ga = pa / d;
    gb = pb / d;
    return d;
  }
  ga = da >= db ? 1.0 : 0.0;
  gb = 1.0 - ga;
  return std::max(da, db);
}

}  // namespace

std::string_view obstacle_shape_name(ObstacleShape shape) {
  switch (shape) {
    case ObstacleShape::kSphere:
      return "sphere";
    case ObstacleShape::kBox:
      return "box";
    case ObstacleShape::kCapsule:
      return "capsule";
    case ObstacleShape::kCylinder:
      return "cylinder";
  }
  return "?";
}

Real ObstacleGeometry::distance(const Vec3& q) const {
  switch (shape) {
    case ObstacleShape::kSphere:
      return q.norm() - radius;
    case ObstacleShape::kBox: {
      const Vec3 d = q.cwiseAbs() - 0.5 * size;
      return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
    }
    case ObstacleShape::kCapsule: {
      const Real y = std::clamp(q.y(), -0.5 * height, 0.5 * height);
      return (q - Vec3(0, y, 0)).norm() - radius;
    }
    case ObstacleShape::kCylinder: {
      Real ga, gb;
      return rectangle_distance(std::hypot(q.x(), q.z()), std::abs(q.y()), radius, 0.5 * height, ga,
                                gb);
    }
  }
  return 0;
}

Vec3 ObstacleGeometry::normal(const Vec3& q) const {
  // The direction from the centre (or the axis) out through q; +y where it is undefined.
  const auto outward = [](const Vec3& w) -> Vec3 {
    const Real r = w.norm();
    return r > 0 ? Vec3(w / r) : Vec3(Vec3::UnitY());
  };
  switch (shape) {
    case ObstacleShape::kSphere:
      return outward(q);
    case ObstacleShape::kBox: {
      const Vec3 d = q.cwiseAbs() - 0.5 * size;
      if (d.maxCoeff() > 0) {
        Vec3 n = d.cwiseMax(0.0);
        for (int k = 0; k < 3; ++k) n[k] *= sign_of(q[k]);
        return n.normalized();
      }
      int k;
      d.maxCoeff(&k);
      Vec3 n = Vec3::Zero();
      n[k] = sign_of(q[k]);
      return n;
    }
    case ObstacleShape::kCapsule: {
      const Real y = std::clamp(q.y(), -0.5 * height, 0.5 * height);
      const Vec3 w = q - Vec3(0, y, 0);
      // On the axis of the cylindrical part: out along x.
      return w.norm() > 0 ? outward(w) : Vec3(Vec3::UnitX());
    }
    case ObstacleShape::kCylinder: {
      const Real rho = std::hypot(q.x(), q.z());
      Real ga, gb;
      rectangle_distance(rho, std::abs(q.y()), radius, 0.5 * height, ga, gb);
      const Vec3 radial = rho > 0 ? Vec3(q.x() / rho, 0, q.z() / rho) : Vec3(Vec3::UnitX());
      return (ga * radial + gb * sign_of(q.y()) * Vec3::UnitY()).normalized();
    }
  }
  return Vec3::UnitY();
}

TriangleMesh ObstacleGeometry::mesh() const {
  switch (shape) {
    case ObstacleShape::kSphere:
      return sphere_mesh(radius);
    case ObstacleShape::kBox:
      return box_mesh(size);
    case ObstacleShape::kCapsule:
      return capsule_mesh(radius, height);
    case ObstacleShape::kCylinder:
      return cylinder_mesh(radius, height);
  }
  return {};
}

namespace {

Field<ObstacleSpec> obstacle_center_field() {
  return vec3_field<&ObstacleSpec::center>("center", "m", range_finite(), "finite coordinates",
                                           "The centre at t = 0");
}
Field<ObstacleSpec> obstacle_radius_field() {
  return required(number_field<&ObstacleSpec::geometry, &ObstacleGeometry::radius>(
      "radius", "m", range_above(0), "a finite radius > 0 (m)", "Radius"));
}
Field<ObstacleSpec> obstacle_rotation_field() {
  return vec3_field<&ObstacleSpec::rotation_degrees>(
      "rotation_degrees", "degrees", range_finite(), "finite angles (degrees)",
      "Rotation at t = 0 about x, then y, then z (axes fixed in space)");
}

// The rows of one shape: center, the shape's own, then rotation, motion and spin.
FieldTable<ObstacleSpec> obstacle_table(std::string_view name, std::string_view title,
                                        std::vector<Field<ObstacleSpec>> own) {
  std::vector<Field<ObstacleSpec>> fields{obstacle_center_field()};
  for (Field<ObstacleSpec>& f : own) fields.push_back(std::move(f));
  fields.push_back(obstacle_rotation_field());
  fields.push_back(obstacle_motion_field<&ObstacleSpec::motion>());
  fields.push_back(obstacle_spin_field<&ObstacleSpec::angular_velocity_degrees>());
  return FieldTable<ObstacleSpec>{name, "terrains[i]", title, std::move(fields)};
}

}  // namespace

const FieldTable<ObstacleSpec>& obstacle_fields(ObstacleShape shape) {
  static const FieldTable<ObstacleSpec> sphere =
      obstacle_table("ObstacleSpec (sphere)", "A sphere obstacle", {obstacle_radius_field()});
  static const FieldTable<ObstacleSpec> box =
      obstacle_table("ObstacleSpec (box)", "An oriented box obstacle",
                     {vec3_each_field<&ObstacleSpec::geometry, &ObstacleGeometry::size>(
                         "size", "m", range_above(0), "three finite edge lengths > 0 (m)",
                         "Edge lengths along its own x, y, z")});
  static const FieldTable<ObstacleSpec> capsule = obstacle_table(
      "ObstacleSpec (capsule)", "A capsule obstacle, its axis along its own y",
      {obstacle_radius_field(),
       required(number_field<&ObstacleSpec::geometry, &ObstacleGeometry::height>(
           "height", "m", range_at_least(0), "a finite length >= 0 between the caps (m)",
           "Length between the caps' centres"))});
  static const FieldTable<ObstacleSpec> cylinder = obstacle_table(
      "ObstacleSpec (cylinder)", "A capped cylinder obstacle, its axis along its own y",
      {obstacle_radius_field(),
       required(number_field<&ObstacleSpec::geometry, &ObstacleGeometry::height>(
           "height", "m", range_above(0), "a finite length > 0 (m)", "Length along the axis"))});
  switch (shape) {
    case ObstacleShape::kSphere:
      return sphere;
    case ObstacleShape::kBox:
      return box;
    case ObstacleShape::kCapsule:
      return capsule;
    case ObstacleShape::kCylinder:
      return cylinder;
  }
  return sphere;
}

void ObstacleSpec::validate(const std::string& prefix) const {
  validate_fields(obstacle_fields(geometry.shape), *this, prefix);
}

std::unique_ptr<Terrain> ObstacleSpec::make() const {
  return std::make_unique<Obstacle>(*this, contact);
}

void ObstacleSpec::write(Json& j) const { write_fields(obstacle_fields(geometry.shape), *this, j); }

namespace {

std::unique_ptr<TerrainSpec> read_obstacle(JsonFields& f, ObstacleShape shape) {
  auto spec = std::make_unique<ObstacleSpec>();
  spec->geometry.shape = shape;
  read_fields(obstacle_fields(shape), f, *spec, f.prefix());
  return spec;
}

}  // namespace

std::unique_ptr<TerrainSpec> ObstacleSpec::read_sphere(JsonFields& f) {
  return read_obstacle(f, ObstacleShape::kSphere);
}
std::unique_ptr<TerrainSpec> ObstacleSpec::read_box(JsonFields& f) {
  return read_obstacle(f, ObstacleShape::kBox);
}
std::unique_ptr<TerrainSpec> ObstacleSpec::read_capsule(JsonFields& f) {
  return read_obstacle(f, ObstacleShape::kCapsule);
}
std::unique_ptr<TerrainSpec> ObstacleSpec::read_cylinder(JsonFields& f) {
  return read_obstacle(f, ObstacleShape::kCylinder);
}

Obstacle::Obstacle(ObstacleSpec spec, ContactParams contact)
    : Terrain(contact), spec_(std::move(spec)) {
  spec_.validate("obstacle.");
  contact.validate("contact.");
  motion_ = ObstacleMotion(spec_.center, spec_.rotation_degrees, spec_.motion,
                           spec_.angular_velocity_degrees);
}

Real Obstacle::signed_distance(const Vec3& p, Real t) const {
  return spec_.geometry.distance(rotation(t).transpose() * (p - position(t)));
}

Vec3 Obstacle::normal(const Vec3& p, Real t) const {
  const Eigen::Matrix3d r = rotation(t);
  return r * spec_.geometry.normal(r.transpose() * (p - position(t)));
}

Vec3 Obstacle::surface_velocity(const Vec3& p, Real t) const {
  return motion_.velocity(t, [&] {
    const Vec3 closest = p - signed_distance(p, t) * normal(p, t);
    return Vec3(closest - position(t));
  });
}

}  // namespace jelly
