#include <jelly/solvers/run_report.hpp>

#include <cstdio>

namespace jelly {

std::string_view run_status_name(RunStatus status) {
  switch (status) {
    case RunStatus::kCompleted:
      return "completed";
    case RunStatus::kCompletedWithWarnings:
      return "completed_with_warnings";
    case RunStatus::kDiverged:
      return "diverged";
    case RunStatus::kSolverFailed:
      return "solver_failed";
  }
  return "unknown";
}

std::string RunReport::brief() const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%s at t = %.6g s after %ld steps, %.3f s wall",
                std::string(run_status_name(status)).c_str(), t, steps, wall_seconds);
  std::string out = buffer;
  if (!reason.empty()) out += ": " + reason;
  return out;
}

}  // namespace jelly
