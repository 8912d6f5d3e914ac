#pragma once
// Preconditioned conjugate gradients behind the LinearSolver interface, preconditioned either by
// the inverse diagonal (Jacobi) or by a CHOLMOD factor of an earlier matrix ("lagged"), which is
// refreshed only when CG needs more than a few iterations with it or after invalidate().
#include <memory>
#include <vector>

#include <jelly/solvers/linear/cholmod_solver.hpp>
#include <jelly/solvers/linear/linear_solver.hpp>

namespace jelly {

// kJacobi inverts the 3x3 diagonal blocks (block Jacobi) when the matrix has the 3x3-block
// pattern of a SpringJacobian, and the scalar diagonal otherwise.
enum class CgPreconditioner { kJacobi, kLaggedCholesky };

struct CgOptions {
  CgPreconditioner preconditioner = CgPreconditioner::kJacobi;
  Real tolerance = 1e-8;  // stop when |b - A x| <= tolerance |b|
  int max_iterations = 1000;
  // Lagged Cholesky: the factor is refreshed at the next factorize when the CPU time of the last
  // solve exceeded the average cost per solve (factorization included) since the last refresh,
  // which minimises the average cost, or when a solve took more than this many iterations.
  int refactor_iterations = 20;
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
  void multiply(const VecX& x, VecX& y) const;  // y = A x

  bool block3_ = false;  // columns 3j, 3j + 1, 3j + 2 share one row pattern (3x3 blocks)
  std::vector<int> diagonal_block_;     // [N]: value index of diagonal block (0, 0), when block3_
  std::vector<double> inverse_blocks_;  // [9 N]: inverses of the 3x3 diagonal blocks
  // Upper block triangle of A (block3_): for column block j, blocks (i, j) with i <= j, each
  // 9 values row-major; half the memory traffic of the full matrix per mat-vec.
  std::vector<int> upper_start_;    // [N + 1] first block of column block j
  std::vector<int> upper_row_;      // [blocks] row block i
  std::vector<int> upper_source_;   // [blocks] value index of entry (0, 0) of the block in A
  std::vector<Real> upper_values_;  // [9 blocks]
  double factor_seconds_ = 0;       // CPU time of the last refresh of the lagged factor
  double lagged_seconds_ = 0;       // ... plus the CPU time of the solves since
  long lagged_solves_ = 0;          // solves since the last refresh

  CgOptions options_;
  const SparseMatrix* a_ = nullptr;
  VecX inverse_diagonal_, r_, z_, p_, q_;
  std::unique_ptr<CholmodSolver> factor_;
  bool stale_ = true;   // the next factorize must refactor
  bool fresh_ = false;  // the factor is of the current matrix
  long preconditioner_factorizations_ = 0;
};

}  // namespace jelly
