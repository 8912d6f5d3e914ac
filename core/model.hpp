#pragma once
// The mass-spring model: particle masses, springs with dampers (struct-of-arrays), gravity, and
// the bodies they form, with pinned particles and external forces.
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/pins.hpp>
#include <jelly/core/state.hpp>
#include <jelly/core/types.hpp>

// Springs with dampers between particle pairs, stored once each as parallel arrays
// (struct-of-arrays) for the force loop, with their type and coefficients.
namespace jelly {

// The three types of springs of the seed's lattice.
enum class SpringType : std::uint8_t { kStructural = 0, kShear = 1, kBending = 2 };
inline constexpr int kSpringTypeCount = 3;           // the number of SpringType values
std::string_view spring_type_name(SpringType type);  // "structural", "shear", "bending"

// Stiffness ks (N/m) and damping kd (N s/m) of one spring type.
struct SpringCoefficients {
  Real ks = 1400;  // N/m
  Real kd = 50;    // N s/m
};

// Springs stored once each, as parallel arrays (struct-of-arrays) for the force loop.
struct Springs {
  std::vector<int> a;             // first particle of each spring
  std::vector<int> b;             // second particle
  std::vector<Real> rest_length;  // m
  std::vector<Real> ks;           // N/m
  std::vector<Real> kd;           // N s/m
  std::vector<SpringType> type;   // structural, shear or bending

  int size() const { return static_cast<int>(a.size()); }  // the number of springs
  void add(int a_index, int b_index, Real rest, SpringCoefficients c,
           SpringType t);         // appends one spring
  int count(SpringType t) const;  // the number of springs of type t
  // Sets ks and kd of every spring of type t.
  void set_coefficients(SpringType t, SpringCoefficients c);
  // Appends `other` with its particle indices offset by `shift`.
  void append(const Springs& other, int shift);
};

}  // namespace jelly

// The triangle surface a person sees of a body: triangles over vertices that follow the
// particles, each vertex a fixed weighted sum of particle positions (a particle itself, or a point
// embedded in a lattice cell with trilinear weights).
namespace jelly {

using Triangle = std::array<int, 3>;  // three vertex indices
// Vertex positions, one row each.
using RowMatrixX3 = Eigen::Matrix<Real, Eigen::Dynamic, 3, Eigen::RowMajor>;

// The triangle surface a person sees of a body: vertices that are weighted sums of particles.
struct Surface {
  std::vector<Triangle> triangles;  // vertex indices, counter-clockwise seen from outside
  // Vertex v = sum over k in [offsets[v], offsets[v + 1]) of weights[k] * x[particles[k]].
  std::vector<int> offsets{0};
  std::vector<int> particles;  // the particles of each vertex's sum
  std::vector<Real> weights;   // their weights

  // The number of vertices.
  int num_vertices() const { return static_cast<int>(offsets.size()) - 1; }
  // The number of triangles.
  int num_triangles() const { return static_cast<int>(triangles.size()); }
  bool empty() const { return triangles.empty(); }  // true for a body without a surface
  // A vertex that is particle p itself.
  void add_particle_vertex(int p);
  // A vertex that is a weighted sum of particles (weights sum to 1).
  void add_vertex(const int* vertex_particles, const Real* vertex_weights, int count);
  // Adds `shift` to every particle index (a body appended after others).
  void shift_particles(int shift);

  // Vertex v's position at x.
  Vec3 vertex(const VecX& x, int v) const;
  // All vertex positions, one row each.
  void vertices(const VecX& x, RowMatrixX3& out) const;
  // Throws InputError unless every index is in range and every vertex has weights.
  void validate(int num_particles, const std::string& field) const;
};

}  // namespace jelly

// A body of the model: a named range of particles and springs with its own material and render
// surface; and BodyPart, what a body builder (geometry/) returns before it joins a model.
namespace jelly {

// Particles of a body chosen by name (a mesh's vertex group, a lattice corner), body-local.
struct ParticleGroup {
  std::string name;            // the group's name
  std::vector<int> particles;  // body-local particle indices
};

// The volume a body fills, for measuring how much it is crushed (core/body_volume.hpp): the
// lattice's cells (corner c at grid offset (c & 1, (c >> 1) & 1, (c >> 2) & 1)) or a mesh's
// tetrahedra (positively oriented at rest). Both empty: a body without volume (cloth).
struct VolumeElements {
  std::vector<std::array<int, 8>> cells;  // the lattice's cells, 8 corners each
  std::vector<std::array<int, 4>> tets;   // the tetrahedra, 4 corners each

  bool empty() const { return cells.empty() && tets.empty(); }  // true for a body without volume
  // The number of elements.
  long size() const { return static_cast<long>(cells.size() + tets.size()); }
  void shift_particles(int offset);  // adds `offset` to every particle index
};

// What a body builder makes: particles, springs and surface with indices local to the part.
struct BodyPart {
  std::string kind;                   // the body kind that built it ("cube", "box", "cloth", ...)
  VecX mass;                          // [n] kg
  VecX position;                      // [3n] rest positions (m)
  Springs springs;                    // local particle indices
  Surface surface;                    // local particle indices
  Real spacing = 0;                   // typical distance between neighbouring particles (m)
  std::vector<ParticleGroup> groups;  // named groups (local particle indices)
  VolumeElements volume;              // local particle indices
  // A sheet without volume (cloth): its particles keep their contact radius from terrains and
  // obstacles by default (Body::thickness), so the surface they span stays outside them.
  bool sheet = false;

  int num_particles() const { return static_cast<int>(mass.size()); }  // the number of particles
};

// A body of the model: a named range of particles and springs with its material, surface and
// motion.
struct Body {
  std::string name;        // unique in the model; the HDF5 group /particles/<name>
  std::string kind;        // the body kind that built it ("cube", "cloth", ...)
  int first_particle = 0;  // its particles are [first_particle, end_particle())
  int num_particles = 0;   // how many
  int first_spring = 0;    // its springs are [first_spring, end_spring())
  int num_springs = 0;     // how many
  Real spacing = 0;        // typical distance between neighbouring particles (m)
  Real radius = 0;         // contact radius of its particles (m)
  // The distance its particles keep from terrains and obstacles (m), in every contact model and
  // integrator: a sheet's contact radius by default, 0 for a body with volume.
  Real thickness = 0;
  // The body's motion at the start (initial_state): every particle moves with
  // velocity + angular_velocity x (x - c), c the body's centre of mass at rest.
  Vec3 velocity{0, 0, 0};             // m/s
  Vec3 angular_velocity{0, 0, 0};     // rad/s
  Surface surface;                    // global particle indices
  std::vector<ParticleGroup> groups;  // global particle indices
  VolumeElements volume;              // global particle indices
  // Its colour in pictures and exports: sRGB [r, g, b], each in [0, 1]; none = the viewer's
  // palette by body index.
  std::optional<Vec3> color;

  int end_particle() const { return first_particle + num_particles; }  // one past its last particle
  int end_spring() const { return first_spring + num_springs; }        // one past its last spring
  // True when `particle` (a global index) belongs to this body.
  bool contains(int particle) const {
    return particle >= first_particle && particle < end_particle();
  }
};

}  // namespace jelly

// Forces from outside the bodies, applied at every force evaluation besides gravity and the
// springs: a constant force spread over a body by mass, wind (drag towards the air's velocity)
// and point forces on chosen particles; each may vary in time by a sinusoidal gust factor and be
// limited to a time window.
namespace jelly {

// The kinds of ExternalForce.
enum class ExternalForceKind {
  kConstant,  // `vector` (N, the total) spread over the particles in proportion to their masses
  kWind,      // drag (w(t) - v) on each particle, w(t) the air's velocity (`vector`, m/s)
  kPoint,     // `vector` (N) on each particle
};
// Every kind with its scene name and description.
const std::vector<EnumName<ExternalForceKind>>& external_force_kinds();
std::string_view external_force_kind_name(ExternalForceKind kind);  // the scene name of `kind`
// Throws InputError naming `field` for an unknown name.
ExternalForceKind external_force_kind_from_name(std::string_view name, std::string_view field);

// A force from outside the bodies on some particles: constant, wind or point, with an optional
// gust and time window.
struct ExternalForce {
  ExternalForceKind kind = ExternalForceKind::kConstant;  // constant, wind or point
  std::vector<int> particles;                             // global particle indices it acts on
  Vec3 vector{0, 0, 0};     // force (N) or, for wind, air velocity (m/s)
  Real drag = 0;            // wind: N s/m per particle, >= 0
  Real gust = 0;            // vector(t) = vector (1 + gust sin(2 pi gust_frequency t))
  Real gust_frequency = 0;  // Hz, >= 0
  Real start = 0;           // acts for start <= t < end
  Real end = std::numeric_limits<Real>::infinity();  // s

  Vec3 vector_at(Real t) const;  // `vector` with the gust factor at time t
  // Throws InputError naming `prefix`field for a value out of range.
  void validate(int num_particles, const std::string& prefix) const;
};

// f += the external forces at time t on velocities v. `mass` is the model's [N] masses.
void add_external_forces(const std::vector<ExternalForce>& forces, const VecX& mass, Real t,
                         const VecX& v, VecX& f);
// d(f)/d(v) of the external forces is diagonal: damping[i] += drag for each wind particle i
// active at time t (damping has one entry per particle).
void add_external_damping(const std::vector<ExternalForce>& forces, Real t, VecX& damping);

}  // namespace jelly

namespace jelly {

// The simulated system: particles, springs, bodies, gravity, pins and external forces.
struct Model {
  VecX mass;                 // [N] particle masses (kg)
  VecX rest_position;        // [3N] the positions the rest lengths were measured in
  Springs springs;           // every spring of every body, and those between bodies
  Vec3 gravity{0, -9.8, 0};  // m/s^2
  // Named ranges of particles and springs, in order; together they cover all of them.
  std::vector<Body> bodies;
  Pins pins;                                   // pinned particles and the paths they follow
  std::vector<ExternalForce> external_forces;  // forces from outside, besides gravity and springs

  int num_particles() const { return static_cast<int>(mass.size()); }  // N
  int num_dofs() const { return 3 * num_particles(); }  // 3N: the size of the state's vectors
  int num_bodies() const { return static_cast<int>(bodies.size()); }  // the number of bodies

  // Appends a body built by a builder: its particles and springs after the existing ones.
  // `radius` <= 0 takes half the part's spacing; the body's thickness is its radius for a sheet
  // (BodyPart::sheet), else 0. Returns the body's index. Throws InputError
  // for a duplicate or empty name or an inconsistent part.
  int add_body(const std::string& name, BodyPart part, Real radius = 0);
  // The body named `name`, or nullptr.
  const Body* find_body(std::string_view name) const;
  // The body that holds particle i.
  const Body& body_of(int particle) const;

  // Throws InputError when a mass, index, rest length or coefficient is out of range.
  void validate() const;
};

// The model at rest in its construction pose, at time 0.
State rest_state(const Model& model);
// The model in its construction pose at time 0, each body moving as its velocity and
// angular_velocity say (at rest when they are zero).
State initial_state(const Model& model);

}  // namespace jelly
