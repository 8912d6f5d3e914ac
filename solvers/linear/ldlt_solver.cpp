#include <jelly/solvers/linear/detail/ldlt_solver.hpp>

namespace jelly {

LinearResult LdltSolver::analyze(const SparseMatrix& a) {
  ldlt_.analyzePattern(a);
  ++counters_.analyses;
  analyzed_ = ldlt_.info() == Eigen::Success;
  factorized_ = false;
  if (!analyzed_) return LinearResult::failure(LinearStatus::kFailure, "LDLT: analysis failed");
  return {};
}

LinearResult LdltSolver::factorize(const SparseMatrix& a) {
  if (!analyzed_)
    return LinearResult::failure(LinearStatus::kInvalidInput, "LDLT: factorize before analyze");
  factorized_ = false;
  ldlt_.factorize(a);
  ++counters_.factorizations;
  if (ldlt_.info() != Eigen::Success)
    return LinearResult::failure(LinearStatus::kNotPositiveDefinite, "LDLT: zero pivot");
  const Eigen::Index worst = [&] {
    Eigen::Index at = 0;
    ldlt_.vectorD().minCoeff(&at);
    return at;
  }();
  if (!(ldlt_.vectorD()[worst] > 0))
    return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                 "LDLT: matrix not positive definite (pivot " +
                                     std::to_string(worst + 1) + " of " + std::to_string(a.rows()) +
                                     " is not positive)");
  factorized_ = true;
  return {};
}

LinearResult LdltSolver::solve(const VecX& b, VecX& x) {
  if (!factorized_)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "LDLT: solve without a successful factorization");
  ++counters_.solves;
  x = ldlt_.solve(b);
  return {};
}

}  // namespace jelly
