#include <jelly/terrain/detail/mesh_obstacle.hpp>

#include <Eigen/Geometry>
#include <atomic>
#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/terrain/detail/terrain_fields.hpp>

namespace jelly {

namespace {

using detail::quoted;

std::uint64_t next_serial() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

// The last query of this thread: which shape, the point in its frame, the answer.
struct LastQuery {
  std::uint64_t serial = 0;
  Vec3 q = Vec3::Zero();
  MeshDistance::Query answer;
};
thread_local LastQuery last_query;

}  // namespace

MeshObstacleShape::MeshObstacleShape(std::string file_, Real scale_, TriangleMesh scaled_outwards,
                                     Real volume_, Real area_)
    : file(std::move(file_)),
      scale(scale_),
      distance(std::move(scaled_outwards)),
      volume(volume_),
      area(area_),
      serial(next_serial()) {}

std::shared_ptr<const MeshObstacleShape> MeshObstacleSpec::shape(const std::string& prefix) const {
  std::shared_ptr<const MeshObstacleShape> cache = std::atomic_load(&cache_);
  if (cache && cache->file == file && cache->scale == pose.scale) return cache;
  const std::string field = prefix + "file";
  require(!file.empty(), field, "\"\"", "the name of an OBJ, STL or PLY file");
  require(std::isfinite(pose.scale) && pose.scale > 0, prefix + "scale", pose.scale,
          "a finite scale > 0");
  // read_mesh refuses a missing file, no triangle, non-finite coordinates, non-manifold and
  // inconsistently oriented edges.
  MeshFile read = read_mesh(file, field);
  const MeshTopology topology = mesh_topology(read.mesh);
  if (!topology.closed()) {
    const MeshHole& worst = topology.holes.front();  // the largest first
    throw InputError(field, quoted(file),
                     "a closed mesh (the obstacle's inside must be defined); it has " +
                         std::to_string(topology.holes.size()) + " hole(s), the largest " +
                         to_text(worst.diameter) + " across at (" +
                         to_text(worst.centre.transpose()) + ")");
  }
  TriangleMesh mesh = std::move(read.mesh);
  for (Vec3& v : mesh.vertices) v *= pose.scale;
  const Real area = mesh.area();
  Real volume = mesh.enclosed_volume();
  const Real size = mesh.bounds().diagonal().norm();
  require(area > 1e-12 * size * size, field, quoted(file),
          "a mesh of non-zero area (this one has " + to_text(area) + " m^2 after scaling)");
  require(std::abs(volume) > 1e-9 * size * size * size, field, quoted(file),
          "a mesh enclosing a volume (this one encloses " + to_text(volume) +
              " m^3 after scaling: flat or folded onto itself)");
  if (volume < 0) {  // oriented inwards: turned outwards
    for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
    volume = -volume;
  }
  cache =
      std::make_shared<const MeshObstacleShape>(file, pose.scale, std::move(mesh), volume, area);
  std::atomic_store(&cache_, cache);
  return cache;
}

const FieldTable<MeshObstacleSpec>& mesh_obstacle_fields() {
  using M = MeshObstacleSpec;
  static const FieldTable<M> table{
      "MeshObstacleSpec",
      "terrains[i]",
      "A closed triangle mesh obstacle",
      {
          file_field<&M::file>("file", "the name of an OBJ, STL or PLY file",
                               "The closed mesh (OBJ, STL or PLY)"),
          pose_scale_field<&M::pose, &Pose::scale>(),
          pose_position_field<&M::pose, &Pose::position>("Where the mesh's origin is at t = 0"),
          pose_rotation_field<&M::pose, &Pose::rotation_degrees>(),
          obstacle_motion_field<&M::motion>(),
          obstacle_spin_field<&M::angular_velocity_degrees>(),
      },
      // The mesh itself: read and checked.
      [](const M& s, const std::string& prefix) { s.shape(prefix); },
  };
  return table;
}

void MeshObstacleSpec::validate(const std::string& prefix) const {
  validate_fields(mesh_obstacle_fields(), *this, prefix);
}

std::unique_ptr<Terrain> MeshObstacleSpec::make() const {
  return std::make_unique<MeshObstacle>(*this, contact);
}

void MeshObstacleSpec::write(Json& j) const { write_fields(mesh_obstacle_fields(), *this, j); }

std::unique_ptr<TerrainSpec> MeshObstacleSpec::read(JsonFields& f) {
  auto s = std::make_unique<MeshObstacleSpec>();
  read_fields(mesh_obstacle_fields(), f, *s, f.prefix());
  return s;
}

MeshObstacle::MeshObstacle(MeshObstacleSpec spec, ContactParams contact)
    : Terrain(contact), spec_(std::move(spec)) {
  spec_.validate("obstacle.");
  contact.validate("contact.");
  shape_ = spec_.shape("obstacle.");
  motion_ = ObstacleMotion(spec_.pose.position, spec_.pose.rotation_degrees, spec_.motion,
                           spec_.angular_velocity_degrees);
}

MeshDistance::Query MeshObstacle::local_query(const Vec3& p, Real t) const {
  const Vec3 q = rotation(t).transpose() * (p - position(t));
  LastQuery& last = last_query;
  if (last.serial != shape_->serial || last.q != q) {
    // The previous particle's nearest triangle bounds the search (neighbours come in turn).
    last.answer =
        shape_->distance.query(q, last.serial == shape_->serial ? last.answer.triangle : -1);
    last.q = q;
    last.serial = shape_->serial;
  }
  return last.answer;
}

Real MeshObstacle::signed_distance(const Vec3& p, Real t) const {
  return local_query(p, t).distance;
}

Vec3 MeshObstacle::normal(const Vec3& p, Real t) const {
  return rotation(t) * local_query(p, t).normal;
}

Vec3 MeshObstacle::closest_point(const Vec3& p, Real t) const {
  return position(t) + rotation(t) * local_query(p, t).closest;
}

Vec3 MeshObstacle::surface_velocity(const Vec3& p, Real t) const {
  return motion_.velocity(t, [&] { return Vec3(rotation(t) * local_query(p, t).closest); });
}

std::vector<std::pair<std::string, Real>> MeshObstacle::attributes() const {
  return {{"scale", shape_->scale},
          {"triangles", static_cast<Real>(shape_->distance.mesh().num_triangles())},
          {"volume", shape_->volume},
          {"area", shape_->area}};
}

}  // namespace jelly
