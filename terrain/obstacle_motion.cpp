#include <jelly/terrain/detail/obstacle_motion.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <utility>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/pose.hpp>

namespace jelly {

namespace {
constexpr Real kDegree = M_PI / 180;
}  // namespace

void validate_angular_velocity(const Vec3& degrees_per_second, const std::string& field) {
  require(degrees_per_second.allFinite() && degrees_per_second.norm() <= kMaxAngularVelocityDegrees,
          field, degrees_per_second.transpose(),
          "finite rates (degrees per second) whose norm is at most 1e6 (about 2,800 turns a "
          "second)");
}

ObstacleMotion::ObstacleMotion(const Vec3& position, const Vec3& rotation_degrees, Path path,
                               const Vec3& angular_velocity_degrees)
    : position_(position), path_(std::move(path)), omega_(angular_velocity_degrees * kDegree) {
  Pose rotation_only;
  rotation_only.rotation_degrees = rotation_degrees;
  rotation0_ = rotation_only.rotation();
}

Eigen::Matrix3d ObstacleMotion::rotation(Real t) const {
  const Real angle = omega_.norm() * t;
  if (angle == 0) return rotation0_;
  return Eigen::AngleAxisd(angle, omega_.normalized()).toRotationMatrix() * rotation0_;
}

Vec3 ObstacleMotion::position(Real t) const {
  return path_.is_fixed() ? position_ : Vec3(position_ + path_.sample(t).offset);
}

Eigen::Isometry3d ObstacleMotion::pose(Real t) const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation(t);
  pose.translation() = position(t);
  return pose;
}

}  // namespace jelly
