#include <jelly/io/detail/run_limits.hpp>

#include <sys/statvfs.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/io/detail/memory_estimate.hpp>

namespace jelly {

namespace {

// A time increment h is kept at time t only if h > |t| * 2^-40: below that, t + h rounds to t or
// to a time off by more than 1e-12 of a step per step (2^-40 is 9.1e-13).
constexpr double kResolution = 1.0 / 1099511627776.0;

// The shortest text that reads back as x ("0.05", not "0.050000000000000003").
std::string number(double x) {
  char text[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, x);
    if (std::strtod(text, nullptr) == x) break;
  }
  return text;
}

std::string count(double x) {
  char text[32];
  std::snprintf(text, sizeof text, x < 1e15 ? "%.0f" : "%.3g", x);
  return text;
}

// Numbers per frame in a recording: positions, velocities, clock, observables, terrains.
double frame_bytes(double particles, double terrains) {
  return 8 * (6 * particles + 2 + 4 + 3 * 3 + 3 * terrains);
}

}  // namespace

RunEstimate estimate_run(const Scene& scene, Real t_start, bool recording) {
  RunEstimate e;
  const Real dt = scene.integrator.dt;
  const Real span = scene.duration - t_start;
  // Simulator::run_until steps while t < t_end - dt / 2.
  e.steps = span > 0.5 * dt ? std::ceil(span / dt - 0.5) : 0;
  e.frames = 1 + (scene.output_interval > 0
                      ? std::min(e.steps, std::floor(std::max(span, 0.0) / scene.output_interval))
                      : e.steps);
  std::int64_t body_particles = 0, body_springs = 0;
  for (const BodySpec& b : scene.bodies) {
    if (!b.shape) continue;
    body_particles += b.shape->estimated_particles();
    body_springs += b.shape->estimated_springs();
  }
  e.particles = body_particles;
  e.springs = body_springs;
  const double particles = static_cast<double>(body_particles);
  const double springs = static_cast<double>(body_springs);
  e.memory_bytes =
      estimate_memory_bytes(body_particles, body_springs, scene.integrator.name, recording);
  e.recording_bytes = recording ? e.frames * frame_bytes(particles, scene.terrains.size()) +
                                      36 * springs + 32 * particles
                                : 0;
  return e;
}

void check_run_limits(const Scene& scene, Real t_start, const RunLimits& limits,
                      const std::string& output, const std::string& restart) {
  const bool recording = !output.empty();
  const RunEstimate e = estimate_run(scene, t_start, recording);
  const Real dt = scene.integrator.dt;
  const Real t_end = scene.duration;
  const std::string from =
      restart.empty() ? std::string("") : " (the checkpoint of " + restart + ")";

  require(std::isfinite(t_start), "start time" + from, number(t_start), "a finite time");
  if (e.steps < 1) {
    if (!restart.empty()) {
      throw InputError("duration", number(t_end),
                       "the run would take no step: it starts at t = " + number(t_start) + " s" +
                           from + ", and a duration is the time the run ends at: more than " +
                           number(t_start + 0.5 * dt) + " s");
    }
    throw InputError(
        "integrator.dt", number(dt),
        "larger than twice the duration (" + number(t_end) + " s): the run would take no step");
  }
  const double largest_time = std::max(std::abs(t_start), std::abs(t_end));
  require(dt > largest_time * kResolution, "integrator.dt", number(dt),
          "a step that is not lost to rounding at t = " + number(largest_time) + " s: more than " +
              number(largest_time * kResolution) + " s");
  require(e.steps <= limits.max_steps, "integrator.dt", number(dt),
          "a step giving at most " + count(limits.max_steps) + " steps: " + count(e.steps) +
              " steps from t = " + number(t_start) + " s to the duration, " + number(t_end) + " s");
  const Real interval = scene.output_interval;
  if (interval > 0) {
    require(interval > largest_time * kResolution, "output_interval", number(interval),
            "an interval that is not lost to rounding at t = " + number(largest_time) +
                " s: more than " + number(largest_time * kResolution) + " s (0 = every step)");
    // The simulator moves its next output time by one interval at a time.
    require((t_end - t_start) / interval <= limits.max_steps, "output_interval", number(interval),
            "at most " + count(limits.max_steps) + " intervals in the run (0 = every step)");
  }
  if (recording) {
    require(e.frames <= limits.max_frames, "output_interval", number(interval),
            "an interval giving at most " + count(limits.max_frames) + " recorded frames, not " +
                count(e.frames) + " (0 = every step)");
  }
  const double memory = limits.memory_bytes >= 0 ? limits.memory_bytes : available_memory_bytes();
  if (memory >= 0 && e.memory_bytes > memory) {
    // A one-cube scene names its size; others their bodies' particle count.
    const bool one_cube =
        scene.bodies.size() == 1 && scene.bodies[0].shape && scene.bodies[0].shape.is<CubeShape>();
    throw InputError(one_cube ? "cube.n" : "bodies",
                     one_cube ? std::to_string(scene.bodies[0].shape.as<CubeShape>().n)
                              : count(static_cast<double>(e.particles)) + " particles",
                     std::string(one_cube ? "a cube that fits" : "bodies that fit") +
                         " in memory: the run needs about " + bytes_text(e.memory_bytes) + " (" +
                         count(static_cast<double>(e.particles)) + " particles, " +
                         count(static_cast<double>(e.springs)) + " springs, " +
                         scene.integrator.name + "), more than the " + bytes_text(memory) +
                         " available");
  }
  // Compression saves at most about a third of a recording (docs/output.md): refuse only what
  // cannot fit even so.
  if (recording && limits.disk_bytes >= 0 && 0.6 * e.recording_bytes > limits.disk_bytes) {
    throw InputError("-o " + output + ": the recording needs about " +
                     bytes_text(e.recording_bytes) + " (" + count(e.frames) + " frames, about " +
                     bytes_text(0.6 * e.recording_bytes) + " compressed), more than the " +
                     bytes_text(limits.disk_bytes) + " free on its file system");
  }
}

void check_run_until(const Simulator& sim, Real t_end, const RunLimits& limits) {
  const Real t = sim.state().t;
  const Real dt = sim.options().dt;
  require(std::isfinite(t_end), "t_end", number(t_end), "a finite time (s)");
  require(std::isfinite(t), "state.t", number(t), "a finite time (s)");
  if (!(t_end > t + 0.5 * dt)) return;  // no step
  // The time farther from 0 names itself in messages.
  const bool state_largest = std::abs(t) > std::abs(t_end);
  const char* field = state_largest ? "state.t" : "t_end";
  const double largest = std::max(std::abs(t), std::abs(t_end));
  const double value = state_largest ? t : t_end;
  require(dt > largest * kResolution, field, number(value),
          "a time at which the step dt = " + number(dt) + " s is not lost to rounding: |t| < " +
              number(dt / kResolution) + " s");
  const double steps = std::ceil((t_end - t) / dt - 0.5);
  require(steps <= limits.max_steps, "t_end", number(t_end),
          "a time at most " + count(limits.max_steps) + " steps of dt = " + number(dt) +
              " s after the state's t = " + number(t) + " s: the run would take " + count(steps) +
              " steps");
  const Real interval = sim.options().output_interval;
  if (interval > 0) {
    require(interval > largest * kResolution, field, number(value),
            "a time at which the output interval " + number(interval) +
                " s is not lost to rounding: |t| < " + number(interval / kResolution) + " s");
    require((t_end - t) / interval <= limits.max_steps, "t_end", number(t_end),
            "a time at most " + count(limits.max_steps) + " output intervals of " +
                number(interval) + " s after the state's t = " + number(t) + " s");
  }
}

double free_disk_bytes(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::string dir =
      slash == std::string::npos ? std::string(".") : (slash == 0 ? "/" : path.substr(0, slash));
  struct statvfs info {};
  if (statvfs(dir.c_str(), &info) != 0) return -1;
  return static_cast<double>(info.f_bavail) * static_cast<double>(info.f_frsize);
}

}  // namespace jelly
