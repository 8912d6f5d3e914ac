#pragma once
// Preconditioned conjugate gradients behind the LinearSolver interface, preconditioned either by
// the inverse diagonal (Jacobi) or by a CHOLMOD factor of an earlier matrix ("lagged"), which is
// refreshed only when CG needs more than a few iterations with it or after invalidate().
#include <memory>

#include <jelly/solvers/cholmod_solver.hpp>
#include <jelly/solvers/linear_solver.hpp>

namespace jelly {

enum class CgPreconditioner { kJacobi, kLaggedCholesky };

struct CgOptions {
  CgPreconditioner preconditioner = CgPreconditioner::kJacobi;
  Real tolerance = 1e-10;  // stop when |b - A x| <= tolerance |b|
  int max_iterations = 1000;
  // Lagged Cholesky: refactor at the next factorize when a solve took more iterations.
  int refactor_iterations = 6;
  // Lagged Cholesky: when a solve with an old factor has not converged after this many
  // iterations, refactor at once and solve again.
  int lagged_iteration_limit = 30;
  CholmodOptions cholmod;
};

class CgSolver final : public LinearSolver {
 public:
  explicit CgSolver(CgOptions options = {});

  std::string_view name() const override {
    return options_.preconditioner == CgPreconditioner::kJacobi ? "cg_jacobi" : "cg_lagged_cholmod";
  }
  LinearResult analyze(const SparseMatrix& a) override;
  LinearResult factorize(const SparseMatrix& a) override;
  LinearResult solve(const VecX& b, VecX& x) override;
  void invalidate() override { stale_ = true; }
  // The CHOLMOD factorizations done for the lagged preconditioner (counted in counters() too).
  long preconditioner_factorizations() const { return preconditioner_factorizations_; }

 private:
  LinearResult run(const VecX& b, VecX& x, int max_iterations);
  void precondition(const VecX& r, VecX& z);

  CgOptions options_;
  const SparseMatrix* a_ = nullptr;
  VecX inverse_diagonal_, r_, z_, p_, q_;
  std::unique_ptr<CholmodSolver> factor_;
  bool stale_ = true;   // the next factorize must refactor
  bool fresh_ = false;  // the factor is of the current matrix
  long preconditioner_factorizations_ = 0;
};

}  // namespace jelly
