#pragma once
// What a scene says of one body: its name, kind-specific shape, material, contact radius,
// pinned particles and external forces; and how it joins a model (add_body).
#include <optional>
#include <string>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/pins.hpp>
#include <jelly/core/polymorphic_value.hpp>
#include <jelly/geometry/body_shape.hpp>

namespace jelly {

// An axis-aligned box: the points p with min() <= p <= max() in every coordinate (what
// Eigen::AlignedBox3d holds, kept here so that public headers need no <Eigen/Geometry>).
class Box3 {
 public:
  Box3() = default;
  // The box from its lowest corner to its highest (m).
  Box3(const Vec3& min, const Vec3& max) : min_(min), max_(max) {}
  const Vec3& min() const { return min_; }  // the lowest corner
  const Vec3& max() const { return max_; }  // the highest corner
  // Whether p lies in the box, its faces included.
  bool contains(const Vec3& p) const;

 private:
  Vec3 min_{0, 0, 0};
  Vec3 max_{0, 0, 0};
};

// Particles of a body chosen by body-local index, by a box region of the rest pose (world
// coordinates) and/or by a named group of the body (a mesh's vertex group, a cloth corner);
// together: the union. Nothing chosen = every particle of the body.
struct ParticleSelection {
  std::vector<int> indices;  // body-local particle indices
  bool has_region = false;   // true when `region` selects
  Box3 region;               // m, in the rest pose's world coordinates
  std::string group;         // a named group of the body; empty: none

  // True when nothing is chosen: every particle of the body.
  bool selects_all() const { return indices.empty() && !has_region && group.empty(); }
  // Global particle indices, sorted. Throws InputError naming `prefix`field for an index out of
  // range, an unknown group, or a selection that holds no particle.
  std::vector<int> resolve(const Model& model, const Body& body, const std::string& prefix) const;
  // Reads the keys "indices", "region" ({"min": [...], "max": [...]}) and "group".
  static ParticleSelection read(JsonFields& fields);
  // Writes the keys "indices", "region" and "group" that are set.
  void write(Json& object) const;
};

// Pinned particles of a body and the path they follow.
struct PinSpec {
  ParticleSelection select;  // the pinned particles
  Path path;                 // fixed by default
};

// An external force of a body as a scene gives it (ExternalForce once added).
struct ExternalForceSpec {
  ExternalForceKind kind = ExternalForceKind::kConstant;  // constant, wind or point
  ParticleSelection select;                               // the particles it acts on
  Vec3 vector{0, 0, 0};     // "force" (N) or, for wind, "velocity" (m/s)
  Real drag = 0;            // wind: N s/m per particle
  Real gust = 0;            // vector(t) = vector (1 + gust sin(2 pi gust_frequency t))
  Real gust_frequency = 0;  // Hz
  Real start = 0;           // s: acts for start <= t < end
  Real end = std::numeric_limits<Real>::infinity();  // s
};

// A body as a scene gives it: its name, the kind's shape, material, contact radius, start motion,
// pins, forces and colour.
struct BodySpec {
  std::string name = "jelly";         // unique in the scene
  PolymorphicValue<BodyShape> shape;  // the kind's own parameters
  Material material;                  // springs and masses
  Real radius = 0;  // contact radius of its particles (m); 0 = half the lattice spacing
  // The distance its particles keep from terrains and obstacles (m); none = the contact radius
  // for a cloth, 0 for a body with volume.
  std::optional<Real> thickness;
  Vec3 velocity{0, 0, 0};                 // m/s at the start, every particle
  Vec3 angular_velocity{0, 0, 0};         // rad/s at the start, about the centre of mass
  std::vector<PinSpec> pins;              // pinned particles
  std::vector<ExternalForceSpec> forces;  // external forces
  std::optional<Vec3> color;              // sRGB [r, g, b] in [0, 1]; none = the viewer's palette

  // The kind of its shape ("cube", ...), or empty without one.
  std::string_view kind() const { return shape ? shape->kind() : std::string_view(); }
  // Throws InputError naming `prefix`field ("bodies[0].").
  void validate(const std::string& prefix) const;
  // A scene's body object: kind, name, the kind's keys, springs, particle_mass, density, radius,
  // thickness, pins, forces, color.
  static BodySpec read(JsonFields& fields);
  Json to_json() const;  // the scene's body object that read() reads back
};

// Builds the body, adds it to the model, then its pins and external forces. Throws InputError
// naming `prefix`field.
void add_body(Model& model, const BodySpec& spec, const std::string& prefix);

// Reads a scene's "springs" object ({"structural": {"ks": .., "kd": ..}, ...}) into `springs`.
void read_springs(JsonFields& fields, std::array<SpringCoefficients, kSpringTypeCount>& springs);
// The "springs" object of a scene for `springs`.
Json springs_json(const std::array<SpringCoefficients, kSpringTypeCount>& springs);

}  // namespace jelly
