#include <jelly/bench/stability.hpp>

#include <cmath>
#include <map>

#include <jelly/bench/spectral.hpp>
#include <jelly/bench/stability_region.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::bench {

BracketResult find_max_stable_dt(const std::function<RunReport(Real)>& run,
                                 const BracketOptions& o) {
  BracketResult r;
  Real lo = NAN, hi = NAN;
  const auto attempt = [&](Real dt) {
    ++r.runs;
    const RunReport report = run(dt);
    if (report.ok()) return true;
    if (std::isnan(hi) || dt <= hi) {
      r.diverged_at = report.t;
      r.reason = std::string(run_status_name(report.status)) + ": " + report.reason;
    }
    return false;
  };
  Real dt = std::min(std::max(o.dt_start, o.dt_min), o.dt_max);
  if (attempt(dt)) {
    lo = dt;
    while (true) {
      if (lo >= o.dt_max) {
        r.status = "stable_at_max";
        r.dt_stable = lo;
        return r;
      }
      dt = std::min(2 * lo, o.dt_max);
      if (!attempt(dt)) {
        hi = dt;
        break;
      }
      lo = dt;
    }
  } else {
    hi = dt;
    while (true) {
      dt = hi / 2;
      if (dt < o.dt_min) {
        r.status = "unstable_at_min";
        r.dt_unstable = hi;
        return r;
      }
      if (attempt(dt)) {
        lo = dt;
        break;
      }
      hi = dt;
    }
  }
  while (hi / lo > 1 + o.tolerance) {
    const Real mid = std::sqrt(lo * hi);
    if (attempt(mid)) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  r.status = "bracketed";
  r.dt_stable = lo;
  r.dt_unstable = hi;
  return r;
}

void StabilityOptions::validate() const {
  for (const std::string& s : scenes) {
    validate_scene_name(s);
    require(s != "free", "--scenes", s, "slope or elevator (scenes with contact)");
  }
  require(!ks.empty(), "--ks", "(empty)", "at least one stiffness");
  for (Real k : ks) require(std::isfinite(k) && k > 0, "--ks", k, "stiffnesses > 0 N/m");
  require(kd.empty() || kd.size() == ks.size(), "--kd", kd.size(),
          "as many dampings as stiffnesses (" + std::to_string(ks.size()) + ")");
  for (Real k : kd) require(std::isfinite(k) && k >= 0, "--kd", k, "dampings >= 0 N s/m");
  require(std::isfinite(kd_ratio) && kd_ratio >= 0, "--kd-ratio", kd_ratio, "a ratio >= 0 s");
  require(n >= 2 && n <= 60, "--n", n, "an integer in [2, 60]");
  require(std::isfinite(horizon) && horizon > 0, "--horizon", horizon, "a time > 0 s");
  require(bracket.tolerance > 0, "--tolerance", bracket.tolerance, "a relative tolerance > 0");
}

Table run_stability(const StabilityOptions& o) {
  o.validate();
  const std::vector<std::string> integrators =
      o.integrators.empty() ? integrator_names() : o.integrators;
  for (const std::string& name : integrators) make_integrator(name);  // unknown names throw
  Table table("stability",
              "largest stable dt (measured by bisection over the horizon, and predicted from the "
              "spectral radius of M^-1 K with D = (kd/ks) K)",
              {"item", "integrator:s", "implicit", "scene:s", "contact:s", "n", "ks", "kd",
               "horizon", "status:s", "dt_stable", "dt_unstable", "dt_predicted", "rho_k", "rho_d",
               "runs", "diverged_at", "reason:s"});
  std::map<std::size_t, SpectralEstimate> spectra;
  long item = 0;
  for (const std::string& integrator : integrators) {
    for (const std::string& scene : o.scenes) {
      for (std::size_t k = 0; k < o.ks.size(); ++k, ++item) {
        if (!o.shard.owns(item)) continue;
        SceneSpec spec;
        spec.name = scene;
        spec.n = o.n;
        spec.ks = o.ks[k];
        spec.kd = o.kd.empty() ? o.kd_ratio * o.ks[k] : o.kd[k];
        spec.contact = o.contact;
        if (!spectra.count(k)) spectra[k] = estimate_spectrum(build_scene(spec).model);
        const SpectralEstimate& e = spectra[k];
        const double implicit = make_integrator(integrator)->is_implicit() ? 1.0 : 0.0;
        const std::vector<Cell> head{static_cast<double>(item),
                                     integrator,
                                     implicit,
                                     scene,
                                     std::string(contact_model_name(o.contact)),
                                     static_cast<double>(o.n),
                                     spec.ks,
                                     spec.kd,
                                     o.horizon};
        std::vector<Cell> row = head;
        if (is_adaptive_integrator(integrator)) {
          for (Cell c :
               std::vector<Cell>{std::string("skipped_adaptive"), NAN, NAN, NAN, e.rho_k, e.rho_d,
                                 0.0, NAN, std::string("adaptive: reported by tolerance, not dt")})
            row.push_back(c);
          table.add_row(row);
          continue;
        }
        const Real predicted = predicted_max_dt(
            integrator, e.rho_k, spec.ks > 0 ? spec.kd / spec.ks : 0, o.bracket.dt_max);
        BracketOptions bracket = o.bracket;
        if (predicted > 0) bracket.dt_start = predicted;
        const BracketResult r = find_max_stable_dt(
            [&](Real dt) {
              Simulator sim =
                  make_scene_simulator(spec, integrator, dt, o.horizon, o.energy_tolerance);
              return sim.run_until(o.horizon);
            },
            bracket);
        for (Cell c :
             std::vector<Cell>{r.status, r.dt_stable, r.dt_unstable, predicted, e.rho_k, e.rho_d,
                               static_cast<double>(r.runs), r.diverged_at, r.reason})
          row.push_back(c);
        table.add_row(row);
        if (o.progress) {
          *o.progress << "stability item " << item << ": " << integrator << " " << scene << " ks "
                      << spec.ks << ": " << r.status << ", dt " << r.dt_stable << " s (" << r.runs
                      << " runs)" << std::endl;
        }
      }
    }
  }
  return table;
}

}  // namespace jelly::bench
