#pragma once
// Pinned particles: held at their anchor or moved along a prescribed Path. Every integrator
// honours them exactly: their accelerations are the path's during a step, their positions and
// velocities are set to the path's at its end (Integrator::step), and implicit methods make
// them constraints of their solve.
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

// The vertical motion of the elevator as a function of time: a cycle of constant-acceleration
// phases, each optionally ending in a dead stop, repeated forever. The seed cycle is
// +3 m/s^2 for 2 s, dead stop, -3 m/s^2 for 2 s, dead stop.
namespace jelly {

// One phase of the elevator's cycle.
struct MotionPhase {
  Real duration = 2;        // s, > 0
  Real acceleration = 3;    // m/s^2 along +y
  bool stop_at_end = true;  // velocity drops to 0 when the phase ends
};

// The elevator's vertical motion: a cycle of MotionPhase, repeated forever.
class ElevatorMotion {
 public:
  // No phases: the platform stays still. Throws InputError for a phase of non-positive duration
  // or a cycle that does not end at rest (it could not repeat); the message names `field`
  // (a scene passes its JSON path, "terrains[0].motion").
  explicit ElevatorMotion(std::vector<MotionPhase> phases = {}, std::string_view field = "motion");
  // The seed's cycle: +3 m/s^2 for 2 s, dead stop, -3 m/s^2 for 2 s, dead stop.
  static ElevatorMotion seed();
  // Scene JSON: "seed" or a list of phases [{"duration": 2, "acceleration": 3, "stop_at_end":
  // true}, ...]. Throws InputError naming `path`.
  static ElevatorMotion read(const Json& j, const std::string& path);
  // The list of phases.
  Json to_json() const;

  // Height offset from the start, velocity and acceleration along +y at time t >= 0.
  Real offset(Real t) const;
  Real velocity(Real t) const;      // m/s along +y at time t
  Real acceleration(Real t) const;  // m/s^2 along +y at time t

  const std::vector<MotionPhase>& phases() const { return phases_; }  // the cycle
  Real period() const { return period_; }                             // s, the cycle's duration

 private:
  struct Sample {
    Real offset, velocity, acceleration;
  };
  Sample sample(Real t) const;

  std::vector<MotionPhase> phases_;
  Real period_ = 0;
  Real cycle_offset_ = 0;  // displacement over one cycle
};

}  // namespace jelly

// A prescribed translation as a function of time, offset(0) = 0: what drives pinned particles
// and moving obstacles. Fixed; the elevator's cycle of constant-acceleration phases along an
// axis; keyframes joined by straight segments or by cubic segments with continuous velocity; a
// sinusoidal oscillation; a circle; or a constant velocity (a controller's target).
namespace jelly {

// The kinds of Path.
enum class PathKind { kFixed, kPhases, kKeyframes, kOscillation, kCircle, kLinear };

// A path's offset, velocity and acceleration at one time.
struct PathSample {
  Vec3 offset{0, 0, 0};        // m, from where the path starts
  Vec3 velocity{0, 0, 0};      // m/s
  Vec3 acceleration{0, 0, 0};  // m/s^2
};

// A prescribed translation as a function of time, offset(0) = 0: drives pins and moving obstacles.
class Path {
 public:
  Path() = default;  // fixed
  // The elevator's cycle along `axis` (a unit vector is not required; its length scales).
  static Path phases(const Vec3& axis, ElevatorMotion cycle);
  // Offsets at increasing times (the first time >= 0, offset 0 before it); linear between them,
  // held after the last. Throws InputError naming `field` for unsorted times or sizes that differ.
  static Path keyframes(std::vector<Real> times, std::vector<Vec3> offsets,
                        std::string_view field = "keyframes");
  // The same keyframes joined by cubic Hermite segments: the velocity at a keyframe is the
  // slope between its neighbours (Catmull-Rom), 0 at the first and last keyframes and at t = 0
  // (offset 0), so the velocity is continuous and the path starts and ends at rest.
  static Path cubic_keyframes(std::vector<Real> times, std::vector<Vec3> offsets,
                              std::string_view field = "keyframes");
  // A circle about the point `center` (relative to where the path starts) and `axis`, one turn
  // per `period` seconds, counter-clockwise about axis (right-hand rule); the radius is the
  // distance from the start to the axis through center. Throws InputError naming `field` for a
  // zero axis, a radius of 0, or a period that is not finite and > 0.
  static Path circle(const Vec3& center, const Vec3& axis, Real period,
                     std::string_view field = "circle");
  // offset = velocity t (a target moving at a constant velocity; Simulator::set_pin_target).
  static Path linear(const Vec3& velocity, std::string_view field = "linear");
  // amplitude * (sin(2 pi f t + phase) - sin(phase)).
  static Path oscillation(const Vec3& amplitude, Real frequency, Real phase = 0,
                          std::string_view field = "oscillation");

  // Scene JSON: "fixed"; {"kind": "phases", "axis": [0, 1, 0], "phases": [{"duration": 2,
  // "acceleration": 3, "stop_at_end": true}, ...] or "seed"}; {"kind": "keyframes", "times":
  // [...], "offsets": [[x, y, z], ...], "interpolation": "linear" or "cubic"}; {"kind":
  // "oscillation", "amplitude": [x, y, z], "frequency": 1, "phase": 0}; {"kind": "circle",
  // "center": [x, y, z], "axis": [x, y, z], "period": 2}; {"kind": "linear", "velocity": [x, y,
  // z]}. Throws InputError naming `path`.
  static Path read(const Json& j, const std::string& path);
  Json to_json() const;  // the scene JSON that read() reads back

  PathKind kind() const { return kind_; }  // which kind of path
  // True for a fixed path (offset 0 at all times).
  bool is_fixed() const { return kind_ == PathKind::kFixed; }
  PathSample sample(Real t) const;  // offset, velocity and acceleration at time t

  const Vec3& axis() const { return axis_; }                     // phases: the axis
  const ElevatorMotion& cycle() const { return cycle_; }         // phases: the cycle
  const std::vector<Real>& times() const { return times_; }      // keyframes: their times (s)
  const std::vector<Vec3>& offsets() const { return offsets_; }  // keyframes: their offsets (m)
  const Vec3& amplitude() const { return amplitude_; }           // oscillation: the amplitude (m)
  Real frequency() const { return frequency_; }                  // oscillation: Hz
  bool cubic() const { return cubic_; }           // keyframes: true when joined by cubic segments
  const Vec3& center() const { return center_; }  // circle: its centre relative to the start (m)
  Real period() const { return period_; }         // circle: one turn's duration (s)
  const Vec3& velocity() const { return velocity_; }  // linear: m/s
  Real phase() const { return phase_; }               // oscillation: the phase (rad)

 private:
  PathSample sample_cubic(Real t) const;

  PathKind kind_ = PathKind::kFixed;
  Vec3 axis_{0, 1, 0};
  ElevatorMotion cycle_;
  std::vector<Real> times_;
  std::vector<Vec3> offsets_;
  Vec3 amplitude_{0, 0, 0};
  Real frequency_ = 0, phase_ = 0;
  bool cubic_ = false;              // keyframes: cubic Hermite segments
  bool added_start_ = false;        // cubic: (0, 0) was put before the first keyframe
  std::vector<Vec3> tangents_;      // cubic keyframes: velocity at each keyframe
  Vec3 center_{0, 0, 0};            // circle: centre relative to the start
  Vec3 e1_{0, 0, 0}, e2_{0, 0, 0};  // circle: -center and axis x (-center)
  Real period_ = 0;
  Vec3 velocity_{0, 0, 0};  // linear
};

// "fixed", "phases", "keyframes", "oscillation", "circle", "linear".
std::string_view path_kind_name(PathKind kind);

}  // namespace jelly

namespace jelly {

// The pinned particles of a model: each follows its Path from its anchor.
struct Pins {
  std::vector<int> particles;  // global particle indices, each at most once
  std::vector<Vec3> anchors;   // position at t = 0 (where the path's offset is 0)
  std::vector<int> path;       // index into paths, per pin
  std::vector<Path> paths;     // the paths pins follow

  int size() const { return static_cast<int>(particles.size()); }  // the number of pins
  bool empty() const { return particles.empty(); }  // true when no particle is pinned
  // Adds a path and returns its index.
  int add_path(Path p);
  // Pins `particle` at `anchor` (t = 0) moving along paths[path_index]; a particle pinned
  // twice keeps its first pin. Linear in the number of pins (it looks for the particle): many
  // new particles go through add_new.
  void add(int particle, const Vec3& anchor, int path_index);
  void add_fixed(int particle,
                 const Vec3& anchor);  // pins `particle` at `anchor` for ever (a fixed path)
  // The pin of `particle` (its index k), or -1 when it is not pinned.
  int find(int particle) const;
  // Pins `particle` at `anchor` moving along `p`, or gives its pin that anchor and path when it
  // is pinned already (a path no other pin uses is replaced in place: driving a pin every step
  // does not grow `paths`).
  void set(int particle, const Vec3& anchor, Path p);
  // Frees `particle`; false when it was not pinned.
  bool remove(int particle);
  // Pins particles[j] at anchors[j] moving along paths[path_index], in time linear in their
  // number: the caller has checked that none is pinned yet and that each appears once.
  void add_new(const std::vector<int>& particles, const std::vector<Vec3>& anchors, int path_index);
  // The index of a fixed path, added if there is none.
  int fixed_path();
  bool all_fixed() const;  // true when every pin's path is fixed

  Vec3 position(int k, Real t) const;  // the position of pin k at time t
  // Offset, velocity and acceleration of pin k's path at time t.
  PathSample sample(int k, Real t) const { return paths[path[k]].sample(t); }
  // Sets the positions and velocities of the pinned particles to their paths' at time t.
  void apply(Real t, VecX& x, VecX& v) const;
  // Replaces the accelerations of the pinned particles by their paths' at time t.
  void apply_acceleration(Real t, VecX& a) const;
  // Offsets every particle index by `shift` (a body appended after others).
  void shift_particles(int shift);
  // Throws InputError for an index out of range or a non-finite anchor.
  void validate(int num_particles) const;
};

}  // namespace jelly
