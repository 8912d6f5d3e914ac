#pragma once
// A small interface over the sparse SPD solvers of the implicit integrators (CHOLMOD, Eigen
// LDLT, preconditioned CG), so that they can be swapped and compared on identical matrices.
#include <memory>
#include <string>
#include <string_view>

#include <jelly/core/detail/sparse_matrix.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

enum class LinearStatus {
  kSuccess,
  kNotPositiveDefinite,  // a non-positive pivot (direct) or curvature (CG)
  kNotConverged,         // CG reached its iteration limit
  kOutOfMemory,
  kInvalidInput,  // wrong sizes, solve before factorize, CHOLMOD_INVALID, ...
  kFailure,       // anything else the backend reports
};
std::string_view linear_status_name(LinearStatus status);

struct LinearResult {
  LinearStatus status = LinearStatus::kSuccess;
  std::string message;  // the backend's reason when not kSuccess
  int iterations = 0;   // CG iterations of a solve
  Real residual = 0;    // |b - A x| / |b| at the end of a CG solve

  bool ok() const { return status == LinearStatus::kSuccess; }
  static LinearResult failure(LinearStatus status, std::string why) {
    LinearResult r;
    r.status = status;
    r.message = std::move(why);
    return r;
  }
};

// Counters every backend keeps.
struct LinearSolverCounters {
  long analyses = 0;        // symbolic analyses (fill-reducing ordering, elimination tree)
  long factorizations = 0;  // numeric factorizations
  long solves = 0;          // calls of solve()
  long cg_iterations = 0;   // total CG iterations
};

// A symmetric positive definite matrix in full storage (both triangles), compressed columns.
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual std::string_view name() const = 0;
  // Symbolic phase for the pattern of `a` (values are ignored). Call once per pattern.
  virtual LinearResult analyze(const SparseMatrix& a) = 0;
  // Numeric phase for `a`, which must have the analysed pattern and must stay alive and
  // unchanged until the next factorize (iterative backends multiply by it).
  virtual LinearResult factorize(const SparseMatrix& a) = 0;
  // Solves A x = b for the last factorized A. x must have the right size; iterative backends
  // start from its content.
  virtual LinearResult solve(const VecX& b, VecX& x) = 0;
  // The next factorize must not reuse an old factor (lagged backends; e.g. dt changed).
  virtual void invalidate() {}
  // How many threads the backend may use for its own loops (the CHOLMOD backends stay on one).
  virtual void set_threads(int /*threads*/) {}
  const LinearSolverCounters& counters() const { return counters_; }

 protected:
  LinearSolverCounters counters_;
};

}  // namespace jelly
