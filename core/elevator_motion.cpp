#include <jelly/core/pins.hpp>

#include <cmath>
#include <string>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

ElevatorMotion::ElevatorMotion(std::vector<MotionPhase> phases, std::string_view field)
    : phases_(std::move(phases)) {
  Real v = 0;
  for (std::size_t i = 0; i < phases_.size(); ++i) {
    const MotionPhase& p = phases_[i];
    const std::string at = std::string(field) + "[" + std::to_string(i) + "]";
    require(std::isfinite(p.duration) && p.duration > 0, at + ".duration", p.duration,
            "a finite duration > 0 s");
    require(std::isfinite(p.acceleration), at + ".acceleration", p.acceleration,
            "a finite acceleration");
    cycle_offset_ += v * p.duration + 0.5 * p.acceleration * p.duration * p.duration;
    v = p.stop_at_end ? 0 : v + p.acceleration * p.duration;
    period_ += p.duration;
  }
  require(std::abs(v) < 1e-12, field, "a cycle ending at " + to_text(v) + " m/s",
          "a cycle that ends at rest (end it with a dead stop or zero net acceleration)");
}

ElevatorMotion ElevatorMotion::seed() { return ElevatorMotion({{2, 3, true}, {2, -3, true}}); }

ElevatorMotion::Sample ElevatorMotion::sample(Real t) const {
  if (phases_.empty() || t <= 0) return {0, 0, phases_.empty() ? 0 : phases_.front().acceleration};
  const Real cycles = std::floor(t / period_);
  Real local = t - cycles * period_;
  Real offset = cycles * cycle_offset_;
  Real v = 0;
  for (const MotionPhase& p : phases_) {
    if (local < p.duration) {
      return {offset + v * local + 0.5 * p.acceleration * local * local, v + p.acceleration * local,
              p.acceleration};
    }
    offset += v * p.duration + 0.5 * p.acceleration * p.duration * p.duration;
    v = p.stop_at_end ? 0 : v + p.acceleration * p.duration;
    local -= p.duration;
  }
  return {offset, v, 0};  // reached only through rounding at the end of a cycle
}

Real ElevatorMotion::offset(Real t) const { return sample(t).offset; }
Real ElevatorMotion::velocity(Real t) const { return sample(t).velocity; }
Real ElevatorMotion::acceleration(Real t) const { return sample(t).acceleration; }

ElevatorMotion ElevatorMotion::read(const Json& j, const std::string& path) {
  if (j.is_string() && j.get<std::string>() == "seed") return ElevatorMotion::seed();
  if (!j.is_array()) {
    throw InputError(path, json_text(j),
                     "\"seed\" or a list of phases [{\"duration\": 2, \"acceleration\": 3, "
                     "\"stop_at_end\": true}, ...]");
  }
  std::vector<MotionPhase> phases;
  for (std::size_t i = 0; i < j.size(); ++i) {
    JsonFields f(j[i], json_element(path, i));
    MotionPhase p;
    p.duration = f.number("duration");
    p.acceleration = f.number("acceleration");
    p.stop_at_end = f.boolean_or("stop_at_end", p.stop_at_end);
    f.reject_unknown();
    phases.push_back(p);
  }
  return ElevatorMotion(std::move(phases), path);
}

Json ElevatorMotion::to_json() const {
  Json phases = Json::array();
  for (const MotionPhase& p : phases_) {
    phases.push_back({{"duration", p.duration},
                      {"acceleration", p.acceleration},
                      {"stop_at_end", p.stop_at_end}});
  }
  return phases;
}

}  // namespace jelly
