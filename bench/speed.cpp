#include <jelly/bench/speed.hpp>

#include <chrono>
#include <cmath>
#include <memory>

#include <jelly/bench/memory.hpp>
#include <jelly/bench/scenes.hpp>
#include <jelly/bench/stability_region.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/detail/team_chooser.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::bench {

void SpeedOptions::validate() const {
  require(!sizes.empty(), "--sizes", "(empty)", "at least one cube size");
  for (int n : sizes) require(n >= 2 && n <= 100, "--sizes", n, "sizes in [2, 100]");
  require(std::isfinite(dt) && dt > 0, "--dt", dt, "a time step > 0 s");
  require(steps >= 1, "--steps", steps, "an integer >= 1");
  require(warmup_steps >= 0, "--warmup-steps", warmup_steps, "an integer >= 0");
  require(!threads.empty(), "--threads", "(empty)", "at least one thread count");
  for (int t : threads) require(t >= 0, "--threads", t, "thread counts >= 0 (0 = all cores)");
  require(interleave_block >= 1, "--interleave-block", interleave_block, "an integer >= 1");
  require(std::isfinite(ks) && ks > 0, "--ks", ks, "a stiffness > 0 N/m");
  for (const std::string& p : preconditioners)
    if (p != kDirectCholmod && p != kAmgVCycle)
      value_of(cg_preconditioner_kinds(), p, "--preconditioners");
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One row of the table (integrator, size, thread count): its scene, its state and its timers.
struct SpeedRun {
  std::vector<Cell> head;
  int threads = 1;
  // For --threads 0: the team size of each step, chosen as the Simulator chooses it.
  std::unique_ptr<parallel::TeamChooser> chooser;
  bool memory_reset = false;
  SceneParts parts;
  std::unique_ptr<Integrator> method;
  ContactSolver contacts;
  std::unique_ptr<const SpringBands> bands;  // the force loop the Simulator uses
  DivergenceGuard guard;
  State before;
  VecX f;
  double integrator_seconds = 0, contact_seconds = 0, force_probe_seconds = 0;
  long evaluations = 0;
  std::string status = "completed";
  int taken = 0;  // steps, the warm-up included
  int timed = 0;
  Statistics before_timing;

  SpeedRun(std::vector<Cell> row_head, const std::string& integrator, int n, int thread_count,
           Real ks, const IntegratorOptions& options, const Scene* scene = nullptr)
      : head(std::move(row_head)), threads(thread_count) {
    if (threads == 0)
      chooser = std::make_unique<parallel::TeamChooser>(parallel::available_cores());
    if (scene != nullptr) {  // a scene file's bodies and terrains as they are
      parts.model = make_model(*scene);
      parts.state = initial_state(parts.model);
      for (const auto& terrain : scene->terrains) parts.terrains.push_back(make_terrain(*terrain));
      if (!parts.terrains.empty()) lower_onto(*parts.terrains.front());
      method = make_integrator(integrator, options);
      bands = std::make_unique<const SpringBands>(parts.model);
      f.resize(parts.model.num_dofs());
      return;
    }
    SceneSpec spec;
    spec.name = "slope";
    spec.n = n;
    spec.ks = ks;
    parts = build_scene(spec);
    lower_onto(*parts.terrains.front());
    method = make_integrator(integrator, options);
    bands = std::make_unique<const SpringBands>(parts.model);
    f.resize(parts.model.num_dofs());
  }

  // Lowers the bodies onto `terrain` (a plane): the deepest particle 1 mm below its surface, so
  // that contacts are active from the first step.
  void lower_onto(const Terrain& terrain) {
    Real lowest = INFINITY;
    for (int i = 0; i < parts.model.num_particles(); ++i)
      lowest = std::min(lowest, terrain.signed_distance(particle(parts.state.x, i), 0));
    const Vec3 normal = terrain.normal(Vec3::Zero(), 0);
    for (int i = 0; i < parts.model.num_particles(); ++i)
      particle(parts.state.x, i) -= (lowest + 1e-3) * normal;
  }

  bool finished(const SpeedOptions& o) const {
    return status != "completed" || taken >= o.warmup_steps + o.steps;
  }

  // Up to `count` more steps (fewer when the run ends).
  void advance(const SpeedOptions& o, int count) {
    const Model& model = parts.model;
    State& state = parts.state;
    for (int k = 0; k < count && !finished(o); ++k, ++taken) {
      const bool timing = taken >= o.warmup_steps;
      if (taken == o.warmup_steps) before_timing = method->statistics();
      const int team = chooser ? chooser->threads() : threads;
      parallel::copy(team, state.x, before.x);
      parallel::copy(team, state.v, before.v);
      const Dynamics dynamics(model, contacts, &parts.terrains, bands.get(), nullptr, team);
      auto start = Clock::now();
      const StepResult result = method->step(dynamics, state, o.dt);
      const double step_time = seconds_since(start);
      start = Clock::now();
      if (result.ok)
        finish_step(result, contacts, nullptr, model, parts.terrains, before, state, o.dt, team);
      const double contact_time = seconds_since(start);
      if (chooser) chooser->record(step_time + contact_time);
      if (timing) {
        integrator_seconds += step_time;
        contact_seconds += contact_time;
        evaluations += dynamics.force_evaluations();
        ++timed;
        // One force evaluation (model forces and the seed contact terms), timed between the
        // steps so that it sees the same load and caches as the steps around it.
        start = Clock::now();
        bands->compute_forces(model, state.x, state.v, f, team);
        contacts.add_forces(state.v, f);
        force_probe_seconds += seconds_since(start);
      }
      if (!result.ok) {
        status = "solver_failed";
      } else if (guard.check(model, state, team)) {
        status = "diverged";
      }
    }
  }

  // The row of the "speed" table and those of "speed_statistics".
  void add_rows(Real o_dt, Table& speed, Table& stats) const {
    const Model& model = parts.model;
    const double force_eval = timed > 0 ? force_probe_seconds / timed : NAN;
    const double per_step = timed > 0 ? 1.0 / timed : NAN;
    const double evals_per_step = evaluations * per_step;
    std::vector<Cell> row = head;
    row.insert(
        row.end(),
        {static_cast<double>(model.num_particles()), static_cast<double>(model.springs.size()),
         o_dt, static_cast<double>(timed), status, static_cast<double>(contacts.contact_count()),
         (integrator_seconds + contact_seconds) * per_step, integrator_seconds * per_step,
         evals_per_step * force_eval, contact_seconds * per_step, evals_per_step,
         model.springs.size() / force_eval, peak_memory_bytes(), memory_reset ? 1.0 : 0.0});
    speed.add_row(row);
    // Counters over the timed steps only (the warm-up subtracted).
    for (const auto& [key, value] : method->statistics()) {
      const auto it = before_timing.find(key);
      const double timed_value = value - (it == before_timing.end() ? 0.0 : it->second);
      stats.add_row({head[0], head[1], head[2], head[3], key, timed_value, timed_value * per_step});
    }
    if (chooser) {
      // Over the whole run, the warm-up included.
      const double all_cores = static_cast<double>(chooser->steps_on_all_cores());
      stats.add_row({head[0], head[1], head[2], head[3], std::string("steps_on_all_cores"),
                     all_cores, all_cores / std::max(1L, chooser->steps())});
    }
  }
};

}  // namespace

std::vector<Table> run_speed(const SpeedOptions& o) {
  o.validate();
  const std::vector<std::string> integrators =
      o.integrators.empty() ? integrator_names() : o.integrators;
  for (const std::string& name : integrators) make_integrator(name);
  Table speed("speed",
              "cost per step on the seed slope (cube lowered onto the slope, contacts active); "
              "seconds per step; force_seconds = evaluations per step x the mean time of one "
              "evaluation timed between the steps",
              {"item", "integrator:s", "n", "threads", "particles", "springs", "dt", "steps",
               "status:s", "contacts", "step_seconds", "integrator_seconds", "force_seconds",
               "contact_seconds", "evaluations_per_step", "springs_per_second", "peak_memory_bytes",
               "memory_per_configuration"});
  Table stats("speed_statistics",
              "the integrator's statistics() over the timed steps (and per timed step)",
              {"item", "integrator:s", "n", "threads", "key:s", "value", "per_step"});
  long item = 0;
  // implicit_euler once per preconditioner asked for (its default when none).
  std::vector<std::pair<std::string, std::string>> variants;  // integrator, preconditioner
  for (const std::string& integrator : integrators) {
    if (integrator == "implicit_euler" && !o.preconditioners.empty()) {
      for (const std::string& p : o.preconditioners) variants.emplace_back(integrator, p);
    } else {
      variants.emplace_back(integrator, "");
    }
  }
  std::vector<Scene> scenes;
  for (const std::string& file : o.scenes) scenes.push_back(load_scene(file));
  // Each scene's rows one after the other (all variants of one scene in a row), else each
  // variant's sizes.
  const std::vector<int> scene_items = scenes.empty() ? std::vector<int>{-1} : [&] {
    std::vector<int> all;
    for (int k = 0; k < static_cast<int>(scenes.size()); ++k) all.push_back(k);
    return all;
  }();
  // With --interleave: a scene's rows of every variant run in alternation (the slope's rows of
  // every variant and size: the ratio of two sizes holds on a machine whose speed changes).
  std::vector<std::unique_ptr<SpeedRun>> runs;
  const auto run_interleaved = [&] {
    for (bool more = !runs.empty(); more;) {
      more = false;
      for (auto& run : runs) {
        run->advance(o, o.interleave_block);
        more = more || !run->finished(o);
      }
    }
    for (const auto& run : runs) run->add_rows(o.dt, speed, stats);
    runs.clear();
  };
  for (const int scene_index : scene_items) {
    const Scene* scene = scene_index >= 0 ? &scenes[scene_index] : nullptr;
    for (const auto& [integrator, preconditioner] : variants) {
      IntegratorOptions options =
          scene != nullptr ? scene->integrator.options : IntegratorOptions{};
      if (preconditioner == kDirectCholmod) {
        options.implicit.linear_solver = ImplicitLinearSolver::kCholmod;
      } else if (preconditioner == kAmgVCycle) {
        options.implicit.cg_preconditioner = CgPreconditionerKind::kAmg;
        options.implicit.amg_cycle = AmgCycle::kV;
      } else if (!preconditioner.empty()) {
        options.implicit.cg_preconditioner =
            value_of(cg_preconditioner_kinds(), preconditioner, "--preconditioners");
      }
      std::string label =
          preconditioner.empty() ? integrator : integrator + "[" + preconditioner + "]";
      if (scene != nullptr) {
        const std::string& file = o.scenes[scene_index];
        const size_t slash = file.find_last_of('/');
        std::string stem = file.substr(slash == std::string::npos ? 0 : slash + 1);
        if (stem.size() > 5 && stem.compare(stem.size() - 5, 5, ".json") == 0)
          stem.resize(stem.size() - 5);
        label += "@" + stem;
      }
      const std::vector<int> sizes = scene != nullptr ? std::vector<int>{scene_index} : o.sizes;
      for (int n : sizes) {
        // The rows of this integrator and size that this shard owns.
        for (int requested_threads : o.threads) {
          const long this_item = item++;
          if (!o.shard.owns(this_item)) continue;
          // 0: the default, each step's team size chosen as the Simulator chooses it.
          const int threads = requested_threads;
          std::vector<Cell> head{static_cast<double>(this_item), label, static_cast<double>(n),
                                 static_cast<double>(threads)};
          if (is_adaptive_integrator(integrator)) {
            std::vector<Cell> row = head;
            row.insert(row.end(), {NAN, NAN, o.dt, 0.0, std::string("skipped_adaptive"), NAN, NAN,
                                   NAN, NAN, NAN, NAN, NAN, NAN, NAN});
            speed.add_row(row);
            continue;
          }
          if (o.interleave) {
            runs.push_back(
                std::make_unique<SpeedRun>(head, integrator, n, threads, o.ks, options, scene));
            continue;
          }
          const bool reset = reset_peak_memory();
          SpeedRun run(head, integrator, n, threads, o.ks, options, scene);
          run.memory_reset = reset;
          run.advance(o, o.warmup_steps + o.steps);
          run.add_rows(o.dt, speed, stats);
        }
      }
    }
    run_interleaved();
  }
  return {speed, stats};
}

}  // namespace jelly::bench
