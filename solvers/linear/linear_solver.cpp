#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

std::string_view linear_status_name(LinearStatus status) {
  switch (status) {
    case LinearStatus::kSuccess:
      return "success";
    case LinearStatus::kNotPositiveDefinite:
      return "not positive definite";
    case LinearStatus::kNotConverged:
      return "not converged";
    case LinearStatus::kOutOfMemory:
      return "out of memory";
    case LinearStatus::kInvalidInput:
      return "invalid input";
    case LinearStatus::kFailure:
      return "failure";
  }
  return "?";
}

}  // namespace jelly
