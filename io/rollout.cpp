#include <jelly/io/detail/rollout.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <thread>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/memory_estimate.hpp>
#include <jelly/io/detail/run_limits.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

// Calls f(k) for k in [0, count) on `threads` threads, each taking the next k in turn. f must
// not throw (each item keeps its own error).
void for_each_on_pool(long count, int threads, const std::function<void(long)>& f) {
  std::atomic<long> next{0};
  auto work = [&] {
    for (long k = next++; k < count; k = next++) f(k);
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

// Rethrows the error of the lowest item that failed; an InputError with `label(k)` before its
// message (the run it belongs to).
void rethrow_first(const std::vector<std::exception_ptr>& errors,
                   const std::function<std::string(long)>& label) {
  for (std::size_t k = 0; k < errors.size(); ++k) {
    if (!errors[k]) continue;
    try {
      std::rethrow_exception(errors[k]);
    } catch (const InputError& e) {
      throw InputError(label(static_cast<long>(k)) + ": " + e.what());
    }
  }
}

// Thrown by FrameKeeper to leave a run when the rollout is stopped.
struct RolloutStopped {};

// Keeps the frames of one run in its part of the rollout's arrays.
class FrameKeeper final : public Observer {
 public:
  FrameKeeper(long capacity, Real* positions, Real* velocities, Real* times,
              const std::atomic<bool>* stop)
      : capacity_(capacity),
        positions_(positions),
        velocities_(velocities),
        times_(times),
        stop_(stop) {}
  void on_frame(const Simulator& sim) override {
    if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) throw RolloutStopped{};
    if (frames_ < capacity_) {
      const VecX& x = sim.state().x;
      std::copy(x.data(), x.data() + x.size(), positions_ + frames_ * x.size());
      if (velocities_ != nullptr) {
        const VecX& v = sim.state().v;
        std::copy(v.data(), v.data() + v.size(), velocities_ + frames_ * v.size());
      }
      times_[frames_] = sim.state().t;
    }
    ++frames_;
  }
  long frames() const { return frames_; }

 private:
  long capacity_;
  Real *positions_, *velocities_, *times_;
  const std::atomic<bool>* stop_;
  long frames_ = 0;
};

}  // namespace

void RolloutOptions::validate() const {
  require(std::isfinite(duration) && duration > 0, "duration", duration, "a time > 0 (s)");
  require(std::isfinite(every), "every", every,
          "a finite interval (s; 0 = every step, < 0 = the scene's output_interval)");
  require(threads >= 0, "threads", threads, "a count >= 0 (0 = all cores)");
}

std::vector<Real> rollout_frame_times(Real dt, Real every, Real duration) {
  // Simulator::run_until: a frame at the start, then after each step while t < end - dt / 2,
  // when t reaches the next output time (within 1e-9 dt), which then moves past t.
  std::vector<Real> times{0};
  Real t = 0, next = 0;
  auto advance = [&] {
    if (every > 0)
      while (next <= t + 1e-9 * dt) next += every;
  };
  advance();
  while (t < duration - 0.5 * dt) {
    t += dt;
    if (every == 0 || t >= next - 1e-9 * dt) {
      times.push_back(t);
      advance();
    }
  }
  return times;
}

RolloutResult rollout(const std::vector<Scene>& scenes, const RolloutOptions& options) {
  options.validate();
  const auto start = std::chrono::steady_clock::now();
  const long runs = static_cast<long>(scenes.size());
  require(runs > 0, "scenes", "an empty list", "at least one run");
  const Real every = options.every < 0 ? scenes[0].output_interval : options.every;
  const int cores = parallel::resolve_threads(options.threads);
  const int pool = static_cast<int>(std::min<long>(cores, runs));
  const int inner = std::max(1, cores / pool);

  // The simulators, built on the pool (a voxelized mesh or a tet mesh takes a while).
  std::vector<std::unique_ptr<Simulator>> sims(runs);
  std::vector<std::vector<Real>> frame_times(runs);
  std::vector<std::exception_ptr> errors(runs);
  for_each_on_pool(runs, pool, [&](long k) {
    try {
      Scene scene = scenes[k];
      scene.duration = options.duration;
      scene.output_interval = every;
      check_run_limits(scene, 0, RunLimits{});
      sims[k] = std::make_unique<Simulator>(make_simulator(scene));
      sims[k]->set_threads(inner);
      frame_times[k] = rollout_frame_times(scene.integrator.dt, every, options.duration);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  });
  rethrow_first(errors, [](long k) { return "scenes[" + std::to_string(k) + "]"; });

  RolloutResult r;
  r.runs = runs;
  r.particles = sims[0]->model().num_particles();
  for (long k = 0; k < runs; ++k) {
    const long n = sims[k]->model().num_particles();
    if (n != r.particles) {
      throw InputError("scenes[" + std::to_string(k) + "]", std::to_string(n) + " particles",
                       "the " + std::to_string(r.particles) +
                           " particles of run 0: a rollout's runs share one particle count");
    }
    r.frames = std::max<long>(r.frames, static_cast<long>(frame_times[k].size()));
  }
  const double frame_values = 3.0 * static_cast<double>(r.particles) * r.frames;
  const double bytes = sizeof(Real) * runs * frame_values * (options.velocities ? 2 : 1);
  const double available = available_memory_bytes();
  require(available < 0 || bytes <= available, "rollout", bytes_text(bytes) + " of frames",
          "arrays that fit in the " + bytes_text(available) +
              " of memory available (fewer runs, a larger `every` or no velocities)");
  const std::size_t values = static_cast<std::size_t>(runs * frame_values);
  r.positions.resize(values);
  if (options.velocities) r.velocities.resize(values);
  r.times.assign(static_cast<std::size_t>(runs * r.frames), kNaN);
  r.run.resize(runs);
  r.threads = pool;

  const std::size_t run_values = static_cast<std::size_t>(frame_values);
  for_each_on_pool(runs, pool, [&](long k) {
    Real* x = r.positions.data() + k * run_values;
    Real* v = options.velocities ? r.velocities.data() + k * run_values : nullptr;
    RolloutRun& out = r.run[k];
    long kept = 0;
    {
      FrameKeeper keeper(r.frames, x, v, r.times.data() + k * r.frames, options.stop);
      try {
        sims[k]->add_observer(keeper);
        const RunReport report = sims[k]->run_until(options.duration);
        out.status = std::string(run_status_name(report.status));
        out.reason = report.reason;
        out.t = report.t;
        out.steps = report.steps;
        out.wall_seconds = report.wall_seconds;
      } catch (const RolloutStopped&) {
        out.status = "stopped";
        out.t = sims[k]->state().t;
        out.steps = sims[k]->total_steps();
        out.reason = "stopped at t = " + to_text(out.t);
      } catch (const std::exception& e) {
        out.status = "failed";
        out.reason = e.what();
        out.t = sims[k]->state().t;
      }
      kept = std::min(keeper.frames(), r.frames);
    }
    out.frames = kept;
    sims[k].reset();  // its memory back before the next run starts
    std::fill(x + kept * 3 * r.particles, x + run_values, kNaN);
    if (v != nullptr) std::fill(v + kept * 3 * r.particles, v + run_values, kNaN);
  });
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

RolloutResult rollout(const std::string& scene_json,
                      const std::vector<std::vector<std::string>>& overrides_per_run,
                      const RolloutOptions& options, const std::string& source,
                      const std::string& base_directory) {
  options.validate();
  const long runs = static_cast<long>(overrides_per_run.size());
  require(runs > 0, "overrides_per_run", "an empty list", "one list of overrides per run");
  const int pool =
      static_cast<int>(std::min<long>(parallel::resolve_threads(options.threads), runs));
  std::vector<Scene> scenes(runs);
  std::vector<std::exception_ptr> errors(runs);
  for_each_on_pool(runs, pool, [&](long k) {
    try {
      for (const std::string& o : overrides_per_run[k]) {
        const std::string path = o.substr(0, o.find('='));
        if (path == "duration" || path == "output_interval") {
          throw InputError(path, "\"" + o + "\"",
                           "no override of it: the runs of a rollout share its duration and "
                           "frame interval (`every`)");
        }
      }
      scenes[k] = parse_scene(scene_json, overrides_per_run[k], source, base_directory);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  });
  auto label = [](long k) { return "overrides_per_run[" + std::to_string(k) + "]"; };
  rethrow_first(errors, label);
  try {
    return rollout(scenes, options);
  } catch (const InputError& e) {
    // Name the run by its overrides' index rather than its scene's.
    std::string message = e.what();
    if (message.rfind("scenes[", 0) == 0) message = "overrides_per_run" + message.substr(6);
    throw InputError(message);
  }
}

}  // namespace jelly
