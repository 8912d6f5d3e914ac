#include <jelly/bench/accuracy.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <jelly/bench/scenes.hpp>
#include <jelly/bench/stability_region.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::bench {

void AccuracyOptions::validate() const {
  require(n >= 2 && n <= 40, "--n", n, "an integer in [2, 40]");
  require(std::isfinite(t_end) && t_end > 0, "--t-end", t_end, "a time > 0 s");
  require(!dts.empty(), "--dt", "(empty)", "at least one time step");
  for (Real dt : dts) require(std::isfinite(dt) && dt > 0, "--dt", dt, "time steps > 0 s");
  require(std::isfinite(reference_dt) && reference_dt >= 0, "--reference-dt", reference_dt,
          "a time step > 0 s (0: the smallest dt / 8)");
  require(std::isfinite(drift_dt) && drift_dt > 0, "--drift-dt", drift_dt, "a time step > 0 s");
  require(std::isfinite(drift_t_end) && drift_t_end > 0, "--drift-t-end", drift_t_end,
          "a time > 0 s");
}

Real rms_position_error(const VecX& x, const VecX& y) {
  return std::sqrt((x - y).squaredNorm() / (x.size() / 3));
}

namespace {

SceneSpec free_scene(const AccuracyOptions& o, Real kd) {
  SceneSpec spec;
  spec.name = "free";
  spec.n = o.n;
  spec.ks = o.ks;
  spec.kd = kd;
  return spec;
}

// The divergence guard without an energy cap: the free jelly is damped, and an energy excursion
// of a stable run is part of what this command measures.
struct FreeRun {
  RunReport report;
  State state;  // at the end of the run
};
FreeRun run_free(const SceneSpec& spec, const std::string& integrator, Real dt, Real t_end) {
  Simulator sim = make_scene_simulator(spec, integrator, dt, t_end, -1);
  FreeRun run;
  run.report = sim.run_until(t_end);
  run.state = sim.state();
  return run;
}

double statistic(const Statistics& s, const std::string& key) {
  const auto it = s.find(key);
  return it == s.end() ? NAN : it->second;
}

}  // namespace

Reference make_reference(const AccuracyOptions& o) {
  Reference r;
  r.dt = o.reference_dt > 0 ? o.reference_dt : *std::min_element(o.dts.begin(), o.dts.end()) / 8;
  const SceneSpec spec = free_scene(o, o.kd);
  const FreeRun coarse = run_free(spec, "rk4", 2 * r.dt, o.t_end);
  const FreeRun fine = run_free(spec, "rk4", r.dt, o.t_end);
  if (!fine.report.ok() || !coarse.report.ok()) {
    throw std::runtime_error("accuracy: the RK4 reference diverged: " + fine.report.brief());
  }
  r.state = fine.state;
  r.error_estimate = rms_position_error(r.state.x, coarse.state.x) / 15;
  return r;
}

std::vector<Table> run_accuracy(const AccuracyOptions& o) {
  o.validate();
  const std::vector<std::string> integrators =
      o.integrators.empty() ? integrator_names() : o.integrators;
  for (const std::string& name : integrators) make_integrator(name);
  Table accuracy("accuracy",
                 "work-precision on the free spinning jelly: RMS position error at t_end against "
                 "the RK4 reference, and the cost",
                 {"item", "integrator:s", "n", "t_end", "dt", "status:s", "error", "wall_seconds",
                  "force_evaluations", "factorizations", "steps"});
  Table reference("accuracy_reference",
                  "the reference: RK4 at reference_dt; error_estimate = Richardson estimate of its "
                  "own error, rms(x(dt) - x(2 dt)) / 15",
                  {"item", "n", "t_end", "reference_dt", "error_estimate"});
  Table drift("drift",
              "energy drift on the undamped free jelly (kd = 0): (E(t_end) - E0) / E0 and the "
              "largest |E - E0| / E0 at 0.01 s samples",
              {"item", "integrator:s", "n", "dt", "t_end", "status:s", "relative_drift",
               "max_relative_deviation", "diverged_at"});
  // Items: 0 the reference, then (integrator, dt) pairs, then one drift run per integrator.
  const long work_items = 1 + static_cast<long>(integrators.size() * o.dts.size());
  bool needs_reference = false;
  for (long item = 0; item < work_items; ++item) needs_reference |= o.shard.owns(item);
  Reference ref;
  if (needs_reference) ref = make_reference(o);
  if (o.shard.owns(0)) {
    reference.add_row({0.0, static_cast<double>(o.n), o.t_end, ref.dt, ref.error_estimate});
  }
  long item = 1;
  const SceneSpec spec = free_scene(o, o.kd);
  for (const std::string& integrator : integrators) {
    for (Real dt : o.dts) {
      const long this_item = item++;
      if (!o.shard.owns(this_item)) continue;
      if (is_adaptive_integrator(integrator)) {
        accuracy.add_row({static_cast<double>(this_item), integrator, static_cast<double>(o.n),
                          o.t_end, dt, std::string("skipped_adaptive"), NAN, NAN, NAN, NAN, NAN});
        continue;
      }
      const FreeRun run = run_free(spec, integrator, dt, o.t_end);
      const RunReport& report = run.report;
      const Real error = report.ok() ? rms_position_error(run.state.x, ref.state.x) : NAN;
      accuracy.add_row({static_cast<double>(this_item), integrator, static_cast<double>(o.n),
                        o.t_end, dt, std::string(run_status_name(report.status)), error,
                        report.wall_seconds, static_cast<double>(report.force_evaluations),
                        statistic(report.statistics, "factorizations"),
                        static_cast<double>(report.steps)});
    }
  }
  const SceneSpec undamped = free_scene(o, 0);
  for (const std::string& integrator : integrators) {
    const long this_item = item++;
    if (!o.shard.owns(this_item)) continue;
    if (is_adaptive_integrator(integrator)) {
      drift.add_row({static_cast<double>(this_item), integrator, static_cast<double>(o.n),
                     o.drift_dt, o.drift_t_end, std::string("skipped_adaptive"), NAN, NAN, NAN});
      continue;
    }
    Simulator sim = make_scene_simulator(undamped, integrator, o.drift_dt, o.drift_t_end, -1);
    const Real e0 = total_energy(sim.model(), sim.state());
    Real deviation = 0;
    RunReport report;
    for (int k = 1; k <= static_cast<int>(std::lround(o.drift_t_end / 0.01)); ++k) {
      report = sim.run_until(std::min(k * 0.01, o.drift_t_end));
      if (!report.ok()) break;
      deviation = std::max(deviation, std::abs(total_energy(sim.model(), sim.state()) - e0) / e0);
    }
    const bool ok = report.ok();
    const Real e = total_energy(sim.model(), sim.state());
    drift.add_row({static_cast<double>(this_item), integrator, static_cast<double>(o.n), o.drift_dt,
                   o.drift_t_end, std::string(run_status_name(report.status)),
                   ok ? (e - e0) / e0 : NAN, ok ? deviation : NAN, ok ? NAN : report.t});
  }
  return {accuracy, reference, drift};
}

Table convergence_orders(const Table& accuracy, const Table& reference) {
  Table orders(
      "order",
      "measured order of convergence: slope of log(error) against log(dt) over completed "
      "runs with error > 100 x the reference's error estimate",
      {"integrator:s", "points", "order_finest", "order_fit", "dt_min_used", "error_at_dt_min"});
  const Real floor = reference.rows() > 0 ? 100 * reference.number(0, "error_estimate") : 0;
  std::vector<std::string> names;
  std::map<std::string, std::vector<std::pair<Real, Real>>> points;
  for (int r = 0; r < accuracy.rows(); ++r) {
    const std::string& name = accuracy.text(r, "integrator");
    if (!points.count(name)) names.push_back(name);
    auto& list = points[name];
    const Real error = accuracy.number(r, "error");
    const std::string& status = accuracy.text(r, "status");
    const bool completed = status == "completed" || status == "completed_with_warnings";
    if (completed && std::isfinite(error) && error > floor && error > 0) {
      list.emplace_back(accuracy.number(r, "dt"), error);
    }
  }
  for (const std::string& name : names) {
    auto list = points[name];
    std::sort(list.begin(), list.end());
    Real finest = NAN, fit = NAN;
    if (list.size() >= 2) {
      finest = std::log(list[1].second / list[0].second) / std::log(list[1].first / list[0].first);
      Real sx = 0, sy = 0, sxx = 0, sxy = 0;
      for (const auto& [dt, e] : list) {
        sx += std::log(dt);
        sy += std::log(e);
        sxx += std::log(dt) * std::log(dt);
        sxy += std::log(dt) * std::log(e);
      }
      const Real k = static_cast<Real>(list.size());
      fit = (k * sxy - sx * sy) / (k * sxx - sx * sx);
    }
    orders.add_row({name, static_cast<double>(list.size()), finest, fit,
                    list.empty() ? NAN : list[0].first, list.empty() ? NAN : list[0].second});
  }
  return orders;
}

}  // namespace jelly::bench
