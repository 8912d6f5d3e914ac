#include <jelly/core/pins.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include <jelly/core/detail/json.hpp>
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
    case PathKind::kCircle:
      return "circle";
    case PathKind::kLinear:
      return "linear";
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

Path Path::cubic_keyframes(std::vector<Real> times, std::vector<Vec3> offsets,
                           std::string_view field) {
  Path p = keyframes(std::move(times), std::move(offsets), field);
  p.cubic_ = true;
  // The points with (0, offset 0) first when the first keyframe is later; Catmull-Rom slopes
  // inside, 0 at both ends.
  std::vector<Real> ts = p.times_;
  std::vector<Vec3> os = p.offsets_;
  p.added_start_ = ts.front() > 0;
  if (p.added_start_) {
    ts.insert(ts.begin(), 0);
    os.insert(os.begin(), Vec3::Zero());
  }
  std::vector<Vec3> slopes(ts.size(), Vec3::Zero());
  for (std::size_t i = 1; i + 1 < ts.size(); ++i)
    slopes[i] = (os[i + 1] - os[i - 1]) / (ts[i + 1] - ts[i - 1]);
  p.times_ = std::move(ts);
  p.offsets_ = std::move(os);
  p.tangents_ = std::move(slopes);
  return p;
}

Path Path::circle(const Vec3& center, const Vec3& axis, Real period, std::string_view field) {
  const std::string f(field);
  require(center.allFinite(), f + ".center", center.transpose(), "finite components");
  require(axis.allFinite() && axis.norm() > 0, f + ".axis", axis.transpose(),
          "a finite, non-zero direction");
  require(std::isfinite(period) && period > 0, f + ".period", period,
          "a finite period > 0 s (the time of one turn)");
  const Vec3 a = axis.normalized();
  // The start relative to the centre, in the circle's plane.
  const Vec3 e1 = -center + center.dot(a) * a;
  require(e1.norm() > 1e-12 * std::max<Real>(1, center.norm()), f + ".center", center.transpose(),
          "a centre off the axis through the start (a radius > 0)");
  Path p;
  p.kind_ = PathKind::kCircle;
  p.center_ = center;
  p.axis_ = axis;
  p.period_ = period;
  p.e1_ = e1;
  p.e2_ = a.cross(e1);
  return p;
}

Path Path::linear(const Vec3& velocity, std::string_view field) {
  require(velocity.allFinite(), std::string(field) + ".velocity", velocity.transpose(),
          "finite components");
  Path p;
  p.kind_ = PathKind::kLinear;
  p.velocity_ = velocity;
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
      if (cubic_) {
        s = sample_cubic(t);
        break;
      }
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
    case PathKind::kCircle: {
      // The start at angle 0: offset = center + cos(w t) e1 + sin(w t) e2 (e1 = start - centre).
      const Real w = 2 * M_PI / period_;
      const Real c = std::cos(w * t), sn = std::sin(w * t);
      s.offset = center_ + c * e1_ + sn * e2_;
      s.velocity = w * (-sn * e1_ + c * e2_);
      s.acceleration = -(w * w) * (c * e1_ + sn * e2_);
      break;
    }
    case PathKind::kLinear:
      s.offset = velocity_ * t;
      s.velocity = velocity_;
      break;
  }
  return s;
}

PathSample Path::sample_cubic(Real t) const {
  PathSample s;
  if (t <= times_.front()) return s;  // at rest at offset 0 (times_ starts at 0)
  if (t >= times_.back()) {
    s.offset = offsets_.back();
    return s;
  }
  const auto it = std::upper_bound(times_.begin(), times_.end(), t);
  const std::size_t i = static_cast<std::size_t>(it - times_.begin()) - 1;
  const Real span = times_[i + 1] - times_[i];
  const Real u = (t - times_[i]) / span;
  const Vec3 &p0 = offsets_[i], &p1 = offsets_[i + 1];
  const Vec3 m0 = span * tangents_[i], m1 = span * tangents_[i + 1];
  // Hermite basis h00 = 2u^3 - 3u^2 + 1, h10 = u^3 - 2u^2 + u, h01 = -2u^3 + 3u^2,
  // h11 = u^3 - u^2, and their first and second derivatives in u.
  const Real u2 = u * u, u3 = u2 * u;
  s.offset = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 +
             (u3 - u2) * m1;
  s.velocity = ((6 * u2 - 6 * u) * p0 + (3 * u2 - 4 * u + 1) * m0 + (-6 * u2 + 6 * u) * p1 +
                (3 * u2 - 2 * u) * m1) /
               span;
  s.acceleration = ((12 * u - 6) * p0 + (6 * u - 4) * m0 + (-12 * u + 6) * p1 + (6 * u - 2) * m1) /
                   (span * span);
  return s;
}

}  // namespace jelly

namespace jelly {

Path Path::read(const Json& j, const std::string& path) {
  if (j.is_string() && j.get<std::string>() == "fixed") return Path();
  JsonFields f(j, path);
  const std::string kind = f.string("kind");
  const auto required_vec3 = [&f](const char* key) {
    const Json* value = f.value(key);
    if (value == nullptr) throw InputError(f.path(key) + " is required");
    return json_vec3(*value, f.path(key));
  };
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
    const std::string interpolation = f.string_or("interpolation", "linear");
    if (interpolation == "cubic") {
      p = Path::cubic_keyframes(std::move(ts), std::move(os), path);
    } else if (interpolation == "linear") {
      p = Path::keyframes(std::move(ts), std::move(os), path);
    } else {
      throw InputError(f.path("interpolation"), "\"" + interpolation + "\"",
                       "\"linear\" or \"cubic\"");
    }
  } else if (kind == "circle") {
    p = Path::circle(required_vec3("center"), f.vec3_or("axis", Vec3::UnitY()), f.number("period"),
                     path);
  } else if (kind == "linear") {
    p = Path::linear(required_vec3("velocity"), path);
  } else if (kind == "oscillation") {
    p = Path::oscillation(f.vec3_or("amplitude", Vec3::Zero()), f.number("frequency"),
                          f.number_or("phase", 0), path);
  } else {
    throw InputError(f.path("kind"), "\"" + kind + "\"",
                     "one of \"fixed\", \"phases\", \"keyframes\", \"oscillation\", "
                     "\"circle\", \"linear\"");
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
      // Cubic keyframes hold (0, 0) first when the scene's first time was later: written back
      // as the scene had them.
      const std::size_t first = cubic_ && added_start_ ? 1 : 0;
      j["times"] = std::vector<Real>(times_.begin() + static_cast<long>(first), times_.end());
      Json offsets = Json::array();
      for (std::size_t i = first; i < offsets_.size(); ++i) offsets.push_back(json_of(offsets_[i]));
      j["offsets"] = offsets;
      if (cubic_) j["interpolation"] = "cubic";
      break;
    }
    case PathKind::kCircle:
      j["center"] = json_of(center_);
      j["axis"] = json_of(axis_);
      j["period"] = period_;
      break;
    case PathKind::kLinear:
      j["velocity"] = json_of(velocity_);
      break;
    case PathKind::kOscillation:
      j["amplitude"] = json_of(amplitude_);
      j["frequency"] = frequency_;
      j["phase"] = phase_;
      break;
  }
  return j;
}

}  // namespace jelly
