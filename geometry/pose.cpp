#include <jelly/geometry/detail/pose.hpp>

#include <cmath>
#include <string>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

Eigen::Matrix3d Pose::rotation() const {
  const Vec3 r = rotation_degrees * (M_PI / 180);
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

void Pose::validate(const std::string& prefix) const {
  require(position.allFinite(), prefix + "position", position.transpose(), "finite coordinates");
  require(rotation_degrees.allFinite(), prefix + "rotation_degrees", rotation_degrees.transpose(),
          "finite angles (degrees)");
  require(std::isfinite(scale) && scale > 0, prefix + "scale", scale, "a finite scale > 0");
}

void Pose::read(JsonFields& f) {
  scale = f.number_or("scale", scale);
  position = f.vec3_or("position", position);
  rotation_degrees = f.vec3_or("rotation_degrees", rotation_degrees);
}

void Pose::write(Json& j) const {
  j["scale"] = scale;
  j["position"] = json_of(position);
  j["rotation_degrees"] = json_of(rotation_degrees);
}

}  // namespace jelly
