#pragma once
// What a run returns: how it ended, where, and what it cost.
#include <string>
#include <string_view>

#include <jelly/solvers/integrators/integrator.hpp>

namespace jelly {

enum class RunStatus {
  kCompleted,     // reached the requested time
  kDiverged,      // NaN, Inf or runaway speed: the divergence guard stopped the run
  kSolverFailed,  // the integrator returned a failure (e.g. a matrix not positive definite)
};
std::string_view run_status_name(RunStatus status);

struct RunReport {
  RunStatus status = RunStatus::kCompleted;
  Real t = 0;          // simulated time reached
  long steps = 0;      // steps taken in this run
  std::string reason;  // why the run stopped early; empty when completed
  double wall_seconds = 0;
  long force_evaluations = 0;
  Statistics statistics;  // the integrator's counters

  bool ok() const { return status == RunStatus::kCompleted; }
  // One line: status, time, steps, wall time (and the reason when it stopped early).
  std::string brief() const;
};

}  // namespace jelly
