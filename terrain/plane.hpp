#pragma once
// A fixed infinite plane (half-space): the floor, or the seed's 20-degree slope.
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

namespace jelly {

// An infinite fixed plane (the seed's slope and floor): contact on the side its normal points to.
class Plane final : public Terrain {
 public:
  // Throws InputError for a zero or non-finite normal or point.
  Plane(const Vec3& point, const Vec3& normal, ContactParams contact = {});
  // The plane through `point` tilted by `angle_degrees` about z: normal (sin a, cos a, 0).
  // The seed slope is slope(20, origin).
  static Plane slope(Real angle_degrees, const Vec3& point = Vec3(0, 0, 0),
                     ContactParams contact = {});

  // "plane".
  std::string_view kind() const override { return "plane"; }
  Real signed_distance(const Vec3& p, Real t) const override;
  Vec3 normal(const Vec3& /*p*/, Real /*t*/) const override { return normal_; }
  Vec3 surface_velocity(const Vec3& p, Real t) const override;
  bool can_contact(const Vec3& /*p*/, Real /*t*/) const override { return true; }
  Vec3 position(Real /*t*/) const override { return point_; }
  // A square of side kRenderSize centred at the point.
  TriangleMesh render_mesh() const override;

  // A point of the plane.
  const Vec3& point() const { return point_; }
  // Its outward unit normal.
  const Vec3& unit_normal() const { return normal_; }

  static constexpr Real kRenderSize = 20;  // m, the side of the square drawn for it

 private:
  Vec3 point_;
  Vec3 normal_;
};

// Scene kind "plane": a fixed plane through `point` with outward `normal` (any length > 0).
struct PlaneSpec final : TerrainSpecOf<PlaneSpec> {
  Vec3 point{0, 0, 0};   // m, a point of the plane
  Vec3 normal{0, 1, 0};  // outward, any length > 0

  // "plane".
  std::string_view kind() const override { return "plane"; }
  void validate(const std::string& prefix) const override;
  std::unique_ptr<Terrain> make() const override;
  void write(Json& object) const override;
  // Reads the kind's keys from `fields`.
  static std::unique_ptr<TerrainSpec> read(JsonFields& fields);
};

// Scene kind "slope": a plane through `point` tilted by `angle_degrees` about z.
struct SlopeSpec final : TerrainSpecOf<SlopeSpec> {
  Real angle_degrees = 20;  // degrees about z: normal (sin a, cos a, 0)
  Vec3 point{0, 0, 0};      // m, a point of the plane

  // "slope".
  std::string_view kind() const override { return "slope"; }
  void validate(const std::string& prefix) const override;
  std::unique_ptr<Terrain> make() const override;
  void write(Json& object) const override;
  // Reads the kind's keys from `fields`.
  static std::unique_ptr<TerrainSpec> read(JsonFields& fields);
};

}  // namespace jelly
