#pragma once
// What a run returns: how it ended, where, and what it cost.
#include <string>
#include <string_view>
#include <vector>

#include <jelly/solvers/integrators/integrator.hpp>

namespace jelly {

enum class RunStatus {
  kCompleted,              // reached the requested time
  kCompletedWithWarnings,  // reached it, but some steps missed the solver's own tolerance
  kDiverged,               // NaN, Inf or runaway speed: the divergence guard stopped the run
  kSolverFailed,  // the integrator returned a failure (e.g. a matrix not positive definite)
};
std::string_view run_status_name(RunStatus status);

struct RunReport {
  RunStatus status = RunStatus::kCompleted;
  Real t = 0;      // simulated time reached
  long steps = 0;  // steps taken in this run
  // Why the run stopped early, or for kCompletedWithWarnings which tolerances how many steps
  // missed ("implicit_euler: Newton did not converge (...) on 111 of 180 steps"); empty when
  // completed.
  std::string reason;
  double wall_seconds = 0;
  long force_evaluations = 0;
  Statistics statistics;  // the integrator's counters
  // What the caller should know that is not a warning: an added force without Jacobians that
  // an implicit integrator treats explicitly within its step, said once per simulator.
  std::vector<std::string> notes;

  // Reached the requested time (with or without warnings).
  bool ok() const {
    return status == RunStatus::kCompleted || status == RunStatus::kCompletedWithWarnings;
  }
  bool has_warnings() const { return status == RunStatus::kCompletedWithWarnings; }
  // One line: status, time, steps, wall time (and the reason when it stopped early).
  std::string brief() const;
};

}  // namespace jelly
