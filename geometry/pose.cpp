#include <jelly/geometry/detail/pose.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

namespace jelly {

Eigen::Matrix3d Pose::rotation() const {
  const Vec3 r = rotation_degrees * (M_PI / 180);
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

const FieldTable<Pose>& pose_fields() {
  static const FieldTable<Pose> table{
      "Pose",
      "bodies[i]",
      "Where a mesh goes: scaled, then rotated, then moved",
      {
          pose_scale_field<&Pose::scale>(),
          pose_position_field<&Pose::position>("Where the mesh's origin goes"),
          pose_rotation_field<&Pose::rotation_degrees>(),
      },
  };
  return table;
}

void Pose::validate(const std::string& prefix) const {
  validate_fields(pose_fields(), *this, prefix);
}

void Pose::read(JsonFields& f) {
  for (const Field<Pose>& field : pose_fields().fields) field.read(f, *this, field.name);
}

void Pose::write(Json& j) const { write_fields(pose_fields(), *this, j); }

}  // namespace jelly
