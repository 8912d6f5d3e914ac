#pragma once
// Rigid obstacles of simple shapes (scene kinds "sphere", "box", "capsule", "cylinder"): a closed
// shape given by its exact signed distance in its own frame, placed at `center` turned by
// `rotation_degrees`, moving along a prescribed path (translation) and turning at a constant
// angular velocity about its centre. The surface velocity at a contact is that of the rigid
// motion at the closest surface point, so a moving or spinning obstacle carries what rests on it.
#include <Eigen/Geometry>
#include <string>
#include <string_view>

#include <jelly/core/pins.hpp>
#include <jelly/terrain/detail/obstacle_motion.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

namespace jelly {

enum class ObstacleShape { kSphere, kBox, kCapsule, kCylinder };

std::string_view obstacle_shape_name(ObstacleShape shape);

// The shape's parameters, in the obstacle's own frame (centre at the origin; the axis of a
// capsule or cylinder along y).
struct ObstacleGeometry {
  ObstacleShape shape = ObstacleShape::kSphere;
  Real radius = 0.5;          // sphere, capsule, cylinder (m), > 0
  Vec3 size = Vec3(1, 1, 1);  // box: edge lengths along its own x, y, z (m), > 0
  Real height = 1;            // cylinder: length; capsule: length between the caps (>= 0)

  // Signed distance of q (own frame): > 0 outside, < 0 inside; and the outward unit normal of
  // the surface nearest q (the distance's gradient; a fixed choice where it is undefined).
  Real distance(const Vec3& q) const;
  Vec3 normal(const Vec3& q) const;
  TriangleMesh mesh() const;
};

// Scene kinds "sphere", "box", "capsule", "cylinder".
struct ObstacleSpec final : TerrainSpecOf<ObstacleSpec> {
  ObstacleGeometry geometry;
  Vec3 center = Vec3::Zero();            // at t = 0
  Vec3 rotation_degrees = Vec3::Zero();  // about x, then y, then z (axes fixed in space)
  Path motion;                           // the centre's offset from `center` at time t
  // Constant spin about the centre (degrees per second about the world's x, y, z axes).
  Vec3 angular_velocity_degrees = Vec3::Zero();

  std::string_view kind() const override { return obstacle_shape_name(geometry.shape); }
  // Throws InputError naming `prefix`field (a scene passes its JSON path, "terrains[0].").
  void validate(const std::string& prefix) const override;
  std::unique_ptr<Terrain> make() const override;
  void write(Json& object) const override;

  static std::unique_ptr<TerrainSpec> read_sphere(JsonFields& fields);
  static std::unique_ptr<TerrainSpec> read_box(JsonFields& fields);
  static std::unique_ptr<TerrainSpec> read_capsule(JsonFields& fields);
  static std::unique_ptr<TerrainSpec> read_cylinder(JsonFields& fields);
};

class Obstacle final : public Terrain {
 public:
  // Throws InputError (fields named "obstacle.") for an invalid spec.
  // Answers with the spec's own contact model (spec.contact).
  explicit Obstacle(ObstacleSpec spec) : Obstacle(spec, spec.contact) {}
  Obstacle(ObstacleSpec spec, ContactParams contact);

  std::string_view kind() const override { return obstacle_shape_name(spec_.geometry.shape); }
  Real signed_distance(const Vec3& p, Real t) const override;
  Vec3 normal(const Vec3& p, Real t) const override;
  // The rigid motion's velocity at the surface point nearest p.
  Vec3 surface_velocity(const Vec3& p, Real t) const override;
  // A closed shape: every particle may touch it (one inside is pushed out through the nearest
  // face).
  bool can_contact(const Vec3& /*p*/, Real /*t*/) const override { return true; }
  Vec3 position(Real t) const override { return motion_.position(t); }
  TriangleMesh render_mesh() const override { return spec_.geometry.mesh(); }
  Eigen::Isometry3d pose(Real t) const override { return motion_.pose(t); }

  const ObstacleSpec& spec() const { return spec_; }
  // The obstacle's orientation at time t (own frame -> world).
  Eigen::Matrix3d rotation(Real t) const { return motion_.rotation(t); }

 private:
  ObstacleSpec spec_;
  ObstacleMotion motion_;
};

}  // namespace jelly
