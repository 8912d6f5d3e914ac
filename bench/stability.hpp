#pragma once
// The largest stable time step: bracketing and bisection over runs that either complete or are
// stopped by the divergence guard, and the `stability` sweep over integrators, stiffnesses and
// scenes with the spectral prediction beside each measured limit.
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <jelly/bench/scenes.hpp>
#include <jelly/bench/shard.hpp>
#include <jelly/bench/table.hpp>
#include <jelly/solvers/run_report.hpp>

namespace jelly::bench {

struct BracketOptions {
  Real dt_start = 1e-3;    // first dt tried (s)
  Real dt_min = 1e-6;      // below this the search gives up: unstable at every dt tried
  Real dt_max = 1.0 / 30;  // above this it stops: stable at every dt tried
  Real tolerance = 0.02;   // stop when dt_unstable / dt_stable <= 1 + tolerance
};

struct BracketResult {
  std::string status;      // "bracketed", "stable_at_max", "unstable_at_min"
  Real dt_stable = NAN;    // the largest dt found stable
  Real dt_unstable = NAN;  // the smallest dt found unstable (above dt_stable)
  int runs = 0;
  Real diverged_at = NAN;  // simulated time at which the run at dt_unstable stopped
  std::string reason;      // and why
};

// `run(dt)` simulates at dt and returns its report; "stable" means report.ok(). The bracket grows
// or shrinks by factors of 2 from dt_start, then bisects geometrically. Stability need not be
// monotone in dt (contact): the result is a stable dt with an unstable one within the tolerance
// above it.
BracketResult find_max_stable_dt(const std::function<RunReport(Real)>& run,
                                 const BracketOptions& options);

struct StabilityOptions {
  std::vector<std::string> integrators;  // empty: every registered integrator
  std::vector<std::string> scenes{"slope", "elevator"};
  std::vector<Real> ks{700, 1400, 2800, 5600};
  std::vector<Real> kd;         // one per ks; empty: kd = kd_ratio * ks
  Real kd_ratio = 50.0 / 1400;  // the seed's kd / ks
  int n = 10;
  Real horizon = 3;  // s
  ContactModel contact = ContactModel::kCoulomb;
  Real energy_tolerance = 1;  // see energy_cap (scenes.hpp)
  BracketOptions bracket;
  Shard shard;
  std::ostream* progress = nullptr;  // one line per finished work item, when set
  void validate() const;
};

// One row per (integrator, scene, ks) work item owned by the shard: table "stability".
Table run_stability(const StabilityOptions& options);

}  // namespace jelly::bench
