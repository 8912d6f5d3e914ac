#pragma once
// Eigen's SimplicialLDLT (AMD ordering) behind the LinearSolver interface: the dependency-free
// reference backend. A non-positive pivot D_ii is reported as kNotPositiveDefinite.
#include <Eigen/SparseCholesky>

#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class LdltSolver final : public LinearSolver {
 public:
  std::string_view name() const override { return "ldlt"; }
  LinearResult analyze(const SparseMatrix& a) override;
  LinearResult factorize(const SparseMatrix& a) override;
  LinearResult solve(const VecX& b, VecX& x) override;

 private:
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> ldlt_;
  bool analyzed_ = false;
  bool factorized_ = false;
};

}  // namespace jelly
