#include <jelly/core/path.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly {

std::string_view path_kind_name(PathKind kind) {
  switch (kind) {
    case PathKind::kFixed:
      return "fixed";
    case PathKind::kPhases:
      return "phases";
    case PathKind::kKeyframes:
      return "keyframes";
    case PathKind::kOscillation:
      return "oscillation";
  }
  return "unknown";
}

Path Path::phases(const Vec3& axis, ElevatorMotion cycle) {
  require(axis.allFinite(), "axis", axis.transpose(), "finite components");
  Path p;
  p.kind_ = PathKind::kPhases;
  p.axis_ = axis;
  p.cycle_ = std::move(cycle);
  return p;
}

Path Path::keyframes(std::vector<Real> times, std::vector<Vec3> offsets, std::string_view field) {
  const std::string f(field);
  require(!times.empty(), f + ".times", "[]", "at least one time");
  require(times.size() == offsets.size(), f + ".offsets", offsets.size(),
          "as many offsets as times (" + std::to_string(times.size()) + ")");
  for (std::size_t i = 0; i < times.size(); ++i) {
    require(std::isfinite(times[i]) && times[i] >= 0 && (i == 0 || times[i] > times[i - 1]),
            f + ".times[" + std::to_string(i) + "]", times[i],
            "finite times >= 0 in increasing order");
    require(offsets[i].allFinite(), f + ".offsets[" + std::to_string(i) + "]",
            offsets[i].transpose(), "finite components");
  }
  Path p;
  p.kind_ = PathKind::kKeyframes;
  p.times_ = std::move(times);
  p.offsets_ = std::move(offsets);
  return p;
}

Path Path::oscillation(const Vec3& amplitude, Real frequency, Real phase, std::string_view field) {
  const std::string f(field);
  require(amplitude.allFinite(), f + ".amplitude", amplitude.transpose(), "finite components");
  require(std::isfinite(frequency) && frequency >= 0, f + ".frequency", frequency,
          "a finite frequency >= 0 Hz");
  require(std::isfinite(phase), f + ".phase", phase, "a finite phase (radians)");
  Path p;
  p.kind_ = PathKind::kOscillation;
  p.amplitude_ = amplitude;
  p.frequency_ = frequency;
  p.phase_ = phase;
  return p;
}

PathSample Path::sample(Real t) const {
  PathSample s;
  switch (kind_) {
    case PathKind::kFixed:
      break;
    case PathKind::kPhases:
      s.offset = cycle_.offset(t) * axis_;
      s.velocity = cycle_.velocity(t) * axis_;
      s.acceleration = cycle_.acceleration(t) * axis_;
      break;
    case PathKind::kKeyframes: {
      if (t <= times_.front()) {
        // Linear from offset 0 at t = 0 to the first keyframe.
        if (times_.front() > 0) {
          s.velocity = offsets_.front() / times_.front();
          s.offset = s.velocity * std::max<Real>(t, 0);
        } else {
          s.offset = offsets_.front();
        }
        break;
      }
      if (t >= times_.back()) {
        s.offset = offsets_.back();
        break;
      }
      const auto it = std::upper_bound(times_.begin(), times_.end(), t);
      const std::size_t i = static_cast<std::size_t>(it - times_.begin()) - 1;
      const Real span = times_[i + 1] - times_[i];
      s.velocity = (offsets_[i + 1] - offsets_[i]) / span;
      s.offset = offsets_[i] + (t - times_[i]) * s.velocity;
      break;
    }
    case PathKind::kOscillation: {
      const Real w = 2 * M_PI * frequency_;
      s.offset = amplitude_ * (std::sin(w * t + phase_) - std::sin(phase_));
      s.velocity = amplitude_ * (w * std::cos(w * t + phase_));
      s.acceleration = amplitude_ * (-w * w * std::sin(w * t + phase_));
      break;
    }
  }
  return s;
}

}  // namespace jelly

namespace jelly {

Path Path::read(const Json& j, const std::string& path) {
  if (j.is_string() && j.get<std::string>() == "fixed") return Path();
  JsonFields f(j, path);
  const std::string kind = f.string("kind");
  Path p;
  if (kind == "fixed") {
    p = Path();
  } else if (kind == "phases") {
    const Vec3 axis = f.vec3_or("axis", Vec3::UnitY());
    const Json* phases = f.value("phases");
    if (phases == nullptr) throw InputError(f.path("phases") + " is required");
    p = Path::phases(axis, ElevatorMotion::read(*phases, f.path("phases")));
  } else if (kind == "keyframes") {
    const Json* times = f.value("times");
    const Json* offsets = f.value("offsets");
    if (times == nullptr || !times->is_array()) {
      throw InputError(f.path("times"), times ? json_text(*times) : "missing",
                       "a list of times [t0, t1, ...]");
    }
    if (offsets == nullptr || !offsets->is_array()) {
      throw InputError(f.path("offsets"), offsets ? json_text(*offsets) : "missing",
                       "a list of offsets [[x, y, z], ...]");
    }
    std::vector<Real> ts;
    std::vector<Vec3> os;
    for (std::size_t i = 0; i < times->size(); ++i) {
      ts.push_back(json_number((*times)[i], json_element(f.path("times"), i)));
    }
    for (std::size_t i = 0; i < offsets->size(); ++i) {
      os.push_back(json_vec3((*offsets)[i], json_element(f.path("offsets"), i)));
    }
    p = Path::keyframes(std::move(ts), std::move(os), path);
  } else if (kind == "oscillation") {
    p = Path::oscillation(f.vec3_or("amplitude", Vec3::Zero()), f.number("frequency"),
                          f.number_or("phase", 0), path);
  } else {
    throw InputError(f.path("kind"), "\"" + kind + "\"",
                     "one of \"fixed\", \"phases\", \"keyframes\", \"oscillation\"");
  }
  f.reject_unknown();
  return p;
}

Json Path::to_json() const {
  Json j;
  j["kind"] = std::string(path_kind_name(kind_));
  switch (kind_) {
    case PathKind::kFixed:
      break;
    case PathKind::kPhases: {
      j["axis"] = json_of(axis_);
      j["phases"] = cycle_.to_json();
      break;
    }
    case PathKind::kKeyframes: {
      j["times"] = times_;
      Json offsets = Json::array();
      for (const Vec3& o : offsets_) offsets.push_back(json_of(o));
      j["offsets"] = offsets;
      break;
    }
    case PathKind::kOscillation:
      j["amplitude"] = json_of(amplitude_);
      j["frequency"] = frequency_;
      j["phase"] = phase_;
      break;
  }
  return j;
}

}  // namespace jelly
