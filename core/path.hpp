#pragma once
// A prescribed translation as a function of time, offset(0) = 0: what drives pinned particles
// and moving obstacles. Fixed; the elevator's cycle of constant-acceleration phases along an
// axis; keyframes joined by straight segments; or a sinusoidal oscillation.
#include <string_view>
#include <vector>

#include <jelly/core/elevator_motion.hpp>
#include <jelly/core/json.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

enum class PathKind { kFixed, kPhases, kKeyframes, kOscillation };

struct PathSample {
  Vec3 offset = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
};

class Path {
 public:
  Path() = default;  // fixed
  // The elevator's cycle along `axis` (a unit vector is not required; its length scales).
  static Path phases(const Vec3& axis, ElevatorMotion cycle);
  // Offsets at increasing times (the first time >= 0, offset 0 before it); linear between them,
  // held after the last. Throws InputError naming `field` for unsorted times or sizes that differ.
  static Path keyframes(std::vector<Real> times, std::vector<Vec3> offsets,
                        std::string_view field = "keyframes");
  // amplitude * (sin(2 pi f t + phase) - sin(phase)).
  static Path oscillation(const Vec3& amplitude, Real frequency, Real phase = 0,
                          std::string_view field = "oscillation");

  // Scene JSON: "fixed"; {"kind": "phases", "axis": [0, 1, 0], "phases": [{"duration": 2,
  // "acceleration": 3, "stop_at_end": true}, ...] or "seed"}; {"kind": "keyframes", "times":
  // [...], "offsets": [[x, y, z], ...]}; {"kind": "oscillation", "amplitude": [x, y, z],
  // "frequency": 1, "phase": 0}. Throws InputError naming `path`.
  static Path read(const Json& j, const std::string& path);
  Json to_json() const;

  PathKind kind() const { return kind_; }
  bool is_fixed() const { return kind_ == PathKind::kFixed; }
  PathSample sample(Real t) const;

  const Vec3& axis() const { return axis_; }
  const ElevatorMotion& cycle() const { return cycle_; }
  const std::vector<Real>& times() const { return times_; }
  const std::vector<Vec3>& offsets() const { return offsets_; }
  const Vec3& amplitude() const { return amplitude_; }
  Real frequency() const { return frequency_; }
  Real phase() const { return phase_; }

 private:
  PathKind kind_ = PathKind::kFixed;
  Vec3 axis_ = Vec3::UnitY();
  ElevatorMotion cycle_;
  std::vector<Real> times_;
  std::vector<Vec3> offsets_;
  Vec3 amplitude_ = Vec3::Zero();
  Real frequency_ = 0, phase_ = 0;
};

std::string_view path_kind_name(PathKind kind);

}  // namespace jelly
