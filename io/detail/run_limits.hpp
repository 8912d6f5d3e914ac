#pragma once
// What a run will take (steps, frames, memory, recording size), checked before it starts: a run
// whose step or frame count is absurd, whose time step is lost to rounding, or which cannot fit
// in memory or on disk is refused with a message naming the field, instead of hanging, running
// zero steps or failing hours later.
#include <cstdint>
#include <string>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

struct RunLimits {
  double max_steps = 1e9;   // about 2 days for the seed cube with rk4
  double max_frames = 1e7;  // recorded frames
  // Bytes the run may use; < 0: what the machine has available (available_memory_bytes()).
  double memory_bytes = -1;
  // Free bytes where the recording goes; < 0: not checked (no recording, or unknown).
  double disk_bytes = -1;
};

struct RunEstimate {
  double steps = 0;            // steps from t_start to the scene's duration
  double frames = 0;           // observer frames (with the first one)
  std::int64_t particles = 0;  // of the scene's bodies, estimated before building them
  std::int64_t springs = 0;
  double memory_bytes = 0;     // estimate_memory_bytes() of the bodies and integrator
  double recording_bytes = 0;  // uncompressed size of a recording of the run
};

// The run of `scene` from t_start (0, or a checkpoint's time) to scene.duration.
RunEstimate estimate_run(const Scene& scene, Real t_start = 0, bool recording = false);

// Throws InputError naming the field (integrator.dt, duration, output_interval, cube.n, or
// `output` for the recording) when the run from t_start would take no step or more than
// limits.max_steps, when a step or output interval is lost to rounding at the run's times, when
// a recording would hold more than limits.max_frames frames or not fit in limits.disk_bytes, or
// when the estimated memory exceeds limits.memory_bytes. `restart` names where t_start came
// from in messages ("" = the scene's start). `output` is the recording's path ("" = none).
void check_run_limits(const Scene& scene, Real t_start, const RunLimits& limits,
                      const std::string& output = "", const std::string& restart = "");

// The step and interval limits of check_run_limits for Simulator::run_until(t_end) from the
// simulator's current time (Python's run_until): throws InputError naming t_end or state.t when
// either is not finite, when options().dt or output_interval is lost to rounding at the run's
// times, or when the run would take more than limits.max_steps steps or intervals. A run that
// takes no step is allowed.
void check_run_until(const Simulator& sim, Real t_end, const RunLimits& limits = {});

// Free bytes on the file system that holds `path` (a file that may not exist yet), or < 0.
double free_disk_bytes(const std::string& path);

}  // namespace jelly
