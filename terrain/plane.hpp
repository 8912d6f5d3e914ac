#pragma once
// A fixed infinite plane (half-space): the floor, or the seed's 20-degree slope.
#include <jelly/terrain/terrain.hpp>

namespace jelly {

class Plane final : public Terrain {
 public:
  // Throws InputError for a zero or non-finite normal or point.
  Plane(const Vec3& point, const Vec3& normal, ContactParams contact = {});
  // The plane through `point` tilted by `angle_degrees` about z: normal (sin a, cos a, 0).
  // The seed slope is slope(20, origin).
  static Plane slope(Real angle_degrees, const Vec3& point = Vec3::Zero(),
                     ContactParams contact = {});

  std::string_view kind() const override { return "plane"; }
  Real signed_distance(const Vec3& p, Real /*t*/) const override { return normal_.dot(p - point_); }
  Vec3 normal(const Vec3& /*p*/, Real /*t*/) const override { return normal_; }
  Vec3 surface_velocity(const Vec3& /*p*/, Real /*t*/) const override { return Vec3::Zero(); }
  bool can_contact(const Vec3& /*p*/, Real /*t*/) const override { return true; }
  Vec3 position(Real /*t*/) const override { return point_; }

  const Vec3& point() const { return point_; }
  const Vec3& unit_normal() const { return normal_; }

 private:
  Vec3 point_;
  Vec3 normal_;
};

}  // namespace jelly
