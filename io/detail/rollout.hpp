#pragma once
// Batched rollouts: many runs of one scene, each with its own overrides (ks, masses, gravity,
// initial velocities, dt, integrator: any `jelly run --set` path), run on a pool of threads,
// their particle positions (and velocities) kept every `every` seconds in one array
// [runs][frames][particles][3]. A run that diverges or fails stops alone; the others go on.
// Each run's frames are the same bits as a Simulator of that scene run alone (any thread count).
#include <atomic>
#include <string>
#include <vector>

#include <jelly/core/types.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {

struct RolloutOptions {
  Real duration = 1;  // s simulated by every run (> 0); a run's own "duration" is refused
  // s between kept frames, the first at t = 0 (as a scene's output_interval: 0 = every step;
  // < 0: the first scene's output_interval).
  Real every = -1;
  bool velocities = false;  // keep velocities too
  // Runs at once (0 = the cores this process may run on). Each run steps on one thread, or on
  // threads / runs threads when there are fewer runs than threads; results do not depend on it.
  int threads = 0;
  // When it becomes true (another thread sets it: a Ctrl-C), each run stops at its next frame
  // and the runs not started do not start; their status is "stopped". Null: never.
  const std::atomic<bool>* stop = nullptr;
  // Throws InputError naming the field (duration, every, threads).
  void validate() const;
};

// How one run of a rollout ended: its status is a RunStatus name ("completed",
// "completed_with_warnings", "diverged", "solver_failed"), "failed" when the run threw (the
// exception's message is then the reason) or "stopped" (RolloutOptions::stop).
struct RolloutRun {
  std::string status;
  std::string reason;  // why it stopped early, or its warnings; empty when completed
  Real t = 0;          // s reached
  long steps = 0;
  long frames = 0;  // frames kept; the frames after them are NaN
  double wall_seconds = 0;
  bool ok() const { return status == "completed" || status == "completed_with_warnings"; }
};

struct RolloutResult {
  long runs = 0, frames = 0, particles = 0;
  // [runs][frames][particles][3], C order; NaN after a run's last frame.
  std::vector<Real> positions;
  std::vector<Real> velocities;  // the same layout; empty unless options.velocities
  std::vector<Real> times;       // [runs][frames] s; NaN after a run's last frame
  std::vector<RolloutRun> run;   // [runs]
  double wall_seconds = 0;       // of the whole rollout
  int threads = 0;               // runs that went at once
};

// The frame times of a run from t = 0 to `duration` with steps of `dt`, one frame every `every`
// seconds (0: every step), exactly as Simulator::run_until emits them (t advances by t += dt).
std::vector<Real> rollout_frame_times(Real dt, Real every, Real duration);

// Runs scenes[k] for k = 0..runs-1 (their duration and output_interval are the options'). All
// scenes must have the same number of particles: a rollout's array has one particle count
// (InputError naming the first scene that differs). Throws InputError for invalid options or
// for a run that jelly run would refuse (too many steps, dt lost to rounding), naming the run.
RolloutResult rollout(const std::vector<Scene>& scenes, const RolloutOptions& options);

// The same for one scene's JSON text and, per run, overrides ("springs.structural.ks=700",
// "bodies[0].velocity=[1,0,0]", "integrator.name=implicit_euler"; see apply_override) applied to
// it. The scenes are parsed on the pool's threads; an invalid one throws InputError naming
// "overrides_per_run[k]" and the scene's field, before any run starts. `source` and
// `base_directory` are parse_scene's.
RolloutResult rollout(const std::string& scene_json,
                      const std::vector<std::vector<std::string>>& overrides_per_run,
                      const RolloutOptions& options, const std::string& source = "scene",
                      const std::string& base_directory = "");

}  // namespace jelly
