#pragma once
// Obstacle kind "mesh": a static closed triangle mesh read from a file (OBJ, STL, PLY), scaled,
// turned and placed like a voxelized body, as an exact signed distance (geometry/mesh_distance:
// the nearest point through a tree over the triangles, the sign from the nearest feature's
// angle-weighted pseudo-normal). Like the other obstacles it may move along a prescribed path
// and spin about its origin (terrain/detail/obstacle_motion.hpp); the surface velocity at a contact
// is the rigid motion's at the nearest surface point.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <jelly/core/pins.hpp>
#include <jelly/geometry/detail/mesh_distance.hpp>
#include <jelly/geometry/detail/pose.hpp>
#include <jelly/terrain/detail/obstacle_motion.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

namespace jelly {

// The mesh of a mesh obstacle as read, checked and scaled, with its distance tree. Shared by the
// copies of a spec and the obstacles made from it.
struct MeshObstacleShape {
  std::string file;
  Real scale = 1;
  MeshDistance distance;     // over the mesh scaled, oriented outwards
  Real volume = 0;           // enclosed (m^3, after scaling)
  Real area = 0;             // of the surface (m^2)
  std::uint64_t serial = 0;  // unique in the process: the key of the per-thread query cache

  MeshObstacleShape(std::string file, Real scale, TriangleMesh scaled_outwards, Real volume,
                    Real area);
};

// Scene kind "mesh": keys file (relative to the scene file's folder), scale, position (where the
// mesh's origin goes at t = 0), rotation_degrees, motion (the origin's offset from position at
// time t), angular_velocity_degrees (spin about the origin).
struct MeshObstacleSpec final : TerrainSpecOf<MeshObstacleSpec> {
  std::string file;  // absolute, or relative to the current directory
  Pose pose;         // scale, rotation_degrees, position at t = 0
  Path motion;
  Vec3 angular_velocity_degrees = Vec3::Zero();

  std::string_view kind() const override { return "mesh"; }
  // Also reads and checks the mesh: InputError naming `prefix`file for a missing or unreadable
  // file, a mesh with no triangle, a non-finite coordinate, an open mesh (holes), edges shared by
  // more than two triangles or oriented inconsistently, and a mesh of zero area or volume.
  void validate(const std::string& prefix) const override;
  std::unique_ptr<Terrain> make() const override;
  void write(Json& object) const override;
  static std::unique_ptr<TerrainSpec> read(JsonFields& fields);

  // The mesh as read, checked and scaled (validate() or the first call reads it; copies of the
  // spec share it).
  std::shared_ptr<const MeshObstacleShape> shape(const std::string& prefix = "") const;

 private:
  mutable std::shared_ptr<const MeshObstacleShape> cache_;
};

class MeshObstacle final : public Terrain {
 public:
  // Throws InputError (fields named "obstacle.") for an invalid spec or mesh.
  // Answers with the spec's own contact model (spec.contact).
  explicit MeshObstacle(MeshObstacleSpec spec) : MeshObstacle(spec, spec.contact) {}
  MeshObstacle(MeshObstacleSpec spec, ContactParams contact);

  std::string_view kind() const override { return "mesh"; }
  Real signed_distance(const Vec3& p, Real t) const override;
  Vec3 normal(const Vec3& p, Real t) const override;
  Vec3 surface_velocity(const Vec3& p, Real t) const override;
  // A closed shape: every particle may touch it (one inside is pushed out through the nearest
  // surface point).
  bool can_contact(const Vec3& /*p*/, Real /*t*/) const override { return true; }
  Vec3 position(Real t) const override { return motion_.position(t); }
  TriangleMesh render_mesh() const override { return shape_->distance.mesh(); }
  Eigen::Isometry3d pose(Real t) const override { return motion_.pose(t); }
  std::vector<std::pair<std::string, Real>> attributes() const override;

  // The nearest surface point of p at time t (world frame).
  Vec3 closest_point(const Vec3& p, Real t) const;
  const MeshObstacleSpec& spec() const { return spec_; }
  const MeshObstacleShape& shape() const { return *shape_; }
  Eigen::Matrix3d rotation(Real t) const { return motion_.rotation(t); }

 private:
  // The query in the mesh's frame; the last one per thread is kept, so that the distance, the
  // normal and the surface velocity of one particle cost one search.
  MeshDistance::Query local_query(const Vec3& p, Real t) const;

  MeshObstacleSpec spec_;
  std::shared_ptr<const MeshObstacleShape> shape_;
  ObstacleMotion motion_;
};

}  // namespace jelly
