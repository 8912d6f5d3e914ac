#pragma once
// The rigid motion of an obstacle (terrain/detail/obstacle.hpp, terrain/detail/mesh_obstacle.hpp):
// its origin at `position` plus a prescribed path's offset at time t, its orientation the initial
// rotation spun about the origin at a constant angular velocity.
#include <string>

#include <Eigen/Geometry>

#include <jelly/core/pins.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

// The fastest spin an obstacle may have: the norm of its angular velocity in degrees per second
// (about 2,800 turns a second; rates near a double's range overflowed the contact velocities).
constexpr Real kMaxAngularVelocityDegrees = 1e6;
// Throws InputError naming `field` unless the rates are finite and their norm is at most
// kMaxAngularVelocityDegrees.
void validate_angular_velocity(const Vec3& degrees_per_second, const std::string& field);

class ObstacleMotion {
 public:
  ObstacleMotion() = default;
  ObstacleMotion(const Vec3& position, const Vec3& rotation_degrees, Path path,
                 const Vec3& angular_velocity_degrees);

  // Orientation (own frame -> world), origin and both together at time t.
  Eigen::Matrix3d rotation(Real t) const;
  Vec3 position(Real t) const;
  Eigen::Isometry3d pose(Real t) const;
  // The velocity at time t of the body's point at offset() from the origin (world frame): the
  // path's velocity plus omega x offset (offset() is called only when the body spins).
  template <class Offset>
  Vec3 velocity(Real t, Offset&& offset) const {
    Vec3 u = path_.is_fixed() ? Vec3(Vec3::Zero()) : path_.sample(t).velocity;
    if (omega_.squaredNorm() > 0) u += omega_.cross(offset());
    return u;
  }

 private:
  Vec3 position_ = Vec3::Zero();
  Path path_;
  Eigen::Matrix3d rotation0_ = Eigen::Matrix3d::Identity();
  Vec3 omega_ = Vec3::Zero();  // rad/s
};

}  // namespace jelly
