#pragma once
// Where a body or mesh is placed: scaled, then rotated (degrees about x, then y, then z), then
// moved by `position`.
#include <string>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct Pose {
  Vec3 position = Vec3::Zero();
  Vec3 rotation_degrees = Vec3::Zero();  // about x, then y, then z (axes fixed in space)
  Real scale = 1;

  Eigen::Matrix3d rotation() const;
  Vec3 apply(const Vec3& p) const { return position + scale * (rotation() * p); }
  // Throws InputError naming `prefix`field for non-finite values or a scale <= 0.
  void validate(const std::string& prefix) const;
  // The scene keys scale, position and rotation_degrees (each optional when read).
  void read(JsonFields& fields);
  void write(Json& object) const;
};

}  // namespace jelly
