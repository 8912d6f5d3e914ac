#pragma once
// The vertical motion of the elevator as a function of time: a cycle of constant-acceleration
// phases, each optionally ending in a dead stop, repeated forever. The seed cycle is
// +3 m/s^2 for 2 s, dead stop, -3 m/s^2 for 2 s, dead stop.
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct MotionPhase {
  Real duration = 2;        // s, > 0
  Real acceleration = 3;    // m/s^2 along +y
  bool stop_at_end = true;  // velocity drops to 0 when the phase ends
};

class ElevatorMotion {
 public:
  // No phases: the platform stays still. Throws InputError for a phase of non-positive duration
  // or a cycle that does not end at rest (it could not repeat); the message names `field`
  // (a scene passes its JSON path, "terrains[0].motion").
  explicit ElevatorMotion(std::vector<MotionPhase> phases = {}, std::string_view field = "motion");
  static ElevatorMotion seed();
  // Scene JSON: "seed" or a list of phases [{"duration": 2, "acceleration": 3, "stop_at_end":
  // true}, ...]. Throws InputError naming `path`.
  static ElevatorMotion read(const Json& j, const std::string& path);
  // The list of phases.
  Json to_json() const;

  // Height offset from the start, velocity and acceleration along +y at time t >= 0.
  Real offset(Real t) const;
  Real velocity(Real t) const;
  Real acceleration(Real t) const;

  const std::vector<MotionPhase>& phases() const { return phases_; }
  Real period() const { return period_; }

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
