#pragma once
// Work-precision on the contact-free spinning jelly (scene "free"): the error at the final time
// against a tight RK4 reference (checked by Richardson extrapolation) for each integrator and dt,
// with its cost; the measured order of convergence; and the energy drift of each integrator on
// the undamped jelly over a long run.
#include <string>
#include <vector>

#include <jelly/bench/shard.hpp>
#include <jelly/bench/table.hpp>
#include <jelly/core/state.hpp>

namespace jelly::bench {

struct AccuracyOptions {
  std::vector<std::string> integrators;  // empty: every registered integrator
  int n = 6;
  Real ks = 1400, kd = 50;
  Real t_end = 1;  // s
  std::vector<Real> dts{2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5};
  Real reference_dt = 0;  // 0: the smallest dt / 8
  Real drift_dt = 1e-3;   // s
  Real drift_t_end = 20;  // s
  Shard shard;
  void validate() const;
};

// RMS over particles of |x_i - y_i|.
Real rms_position_error(const VecX& x, const VecX& y);

struct Reference {
  State state;
  Real dt = 0;
  Real error_estimate = 0;  // Richardson: rms(x(dt) - x(2 dt)) / (2^4 - 1)
};
Reference make_reference(const AccuracyOptions& options);

// Tables "accuracy" (one row per integrator and dt), "accuracy_reference" (one row, item 0) and
// "drift" (one row per integrator), rows limited to the shard's work items.
std::vector<Table> run_accuracy(const AccuracyOptions& options);

// Table "order": per integrator, the slope of log(error) against log(dt) between the two smallest
// completed dts whose error is above 100 times the reference's error estimate ("order_finest"),
// and the least-squares slope over all such dts ("order_fit").
Table convergence_orders(const Table& accuracy, const Table& reference);

}  // namespace jelly::bench
