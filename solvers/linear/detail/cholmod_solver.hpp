#pragma once
// Sparse Cholesky (LL^T) by SuiteSparse CHOLMOD: the symbolic analysis is done once per pattern,
// each factorize is numeric only. CHOLMOD prints nothing; every CHOLMOD status becomes a
// LinearResult with CHOLMOD's reason (a non-positive-definite matrix is a status, not a crash).
#include <memory>
#include <vector>

#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class CholmodSolver final : public LinearSolver {
 public:
  explicit CholmodSolver(CholmodOptions options = {});
  ~CholmodSolver() override;
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  std::string_view name() const override { return "cholmod"; }
  LinearResult analyze(const SparseMatrix& a) override;
  LinearResult factorize(const SparseMatrix& a) override;
  LinearResult solve(const VecX& b, VecX& x) override;
  // Solves A X = B for all columns of B at once (one pass over the factor; projective dynamics
  // solves x, y and z together). X must have B's size.
  LinearResult solve_columns(const Eigen::MatrixXd& b, Eigen::MatrixXd& x);

  // Adds (add = true) or subtracts d[k] >= 0 to the diagonal entry rows[k] of the factorized
  // matrix by a multiple-rank update or downdate of the factor (CHOLMOD Modify: the factor
  // becomes simplicial LDL'; no new analysis or factorization). No allocation after the first.
  LinearResult update_diagonal(const std::vector<int>& rows, const std::vector<Real>& d, bool add);
  // Rank-1 updates and downdates applied since construction.
  long rank_updates() const;

  bool factorized() const;
  // Non-zeros of the factor L (after analyze) and the flop count of the last factorization.
  double factor_non_zeros() const;
  double factor_flops() const;

 private:
  LinearResult solve_raw(const Real* b, Real* x, int columns);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace jelly
