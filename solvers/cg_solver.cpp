#include <jelly/solvers/cg_solver.hpp>

#include <algorithm>
#include <cmath>

namespace jelly {

CgSolver::CgSolver(CgOptions options) : options_(options) {
  if (options_.preconditioner == CgPreconditioner::kLaggedCholesky)
    factor_ = std::make_unique<CholmodSolver>(options_.cholmod);
}

LinearResult CgSolver::analyze(const SparseMatrix& a) {
  if (a.rows() != a.cols() || !a.isCompressed())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: the matrix must be square and compressed");
  const Eigen::Index n = a.rows();
  inverse_diagonal_.setZero(n);
  r_.setZero(n);
  z_.setZero(n);
  p_.setZero(n);
  q_.setZero(n);
  a_ = nullptr;
  stale_ = true;
  ++counters_.analyses;
  if (factor_) {
    LinearResult r = factor_->analyze(a);
    if (!r.ok()) return r;
  }
  return {};
}

LinearResult CgSolver::factorize(const SparseMatrix& a) {
  if (a.rows() != r_.size())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: factorize: the matrix does not have the analysed size");
  a_ = &a;
  if (!factor_) {
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      const Real d = a.coeff(j, j);
      if (!(d > 0)) {
        a_ = nullptr;
        return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                     "CG: diagonal entry " + std::to_string(j + 1) +
                                         " is not positive");
      }
      inverse_diagonal_[j] = 1.0 / d;
    }
    return {};
  }
  fresh_ = false;
  if (stale_ || !factor_->factorized()) {
    LinearResult r = factor_->factorize(a);
    ++counters_.factorizations;
    ++preconditioner_factorizations_;
    if (!r.ok()) {
      a_ = nullptr;
      return r;
    }
    stale_ = false;
    fresh_ = true;
  }
  return {};
}

void CgSolver::precondition(const VecX& r, VecX& z) {
  if (factor_) {
    factor_->solve(r, z);
  } else {
    z = inverse_diagonal_.cwiseProduct(r);
  }
}

LinearResult CgSolver::run(const VecX& b, VecX& x, int max_iterations) {
  const SparseMatrix& a = *a_;
  const Real b_norm = b.norm();
  LinearResult result;
  if (b_norm == 0) {
    x.setZero();
    return result;
  }
  r_ = b;
  r_.noalias() -= a * x;
  Real r_norm = r_.norm();
  const Real target = options_.tolerance * b_norm;
  int k = 0;
  if (r_norm > target) {
    precondition(r_, z_);
    p_ = z_;
    Real rz = r_.dot(z_);
    while (k < max_iterations) {
      q_.noalias() = a * p_;
      const Real curvature = p_.dot(q_);
      if (!(curvature > 0)) {
        result = LinearResult::failure(
            LinearStatus::kNotPositiveDefinite,
            "CG: non-positive curvature p^T A p = " + std::to_string(curvature) +
                " at iteration " + std::to_string(k + 1) + ": matrix not positive definite");
        break;
      }
      const Real alpha = rz / curvature;
      x.noalias() += alpha * p_;
      r_.noalias() -= alpha * q_;
      ++k;
      r_norm = r_.norm();
      if (r_norm <= target || !std::isfinite(r_norm)) break;
      precondition(r_, z_);
      const Real rz_next = r_.dot(z_);
      const Real beta = rz_next / rz;
      rz = rz_next;
      p_ = z_ + beta * p_;
    }
  }
  counters_.cg_iterations += k;
  result.iterations = k;
  result.residual = r_norm / b_norm;
  if (result.ok() && !(r_norm <= target)) {
    result = LinearResult::failure(
        LinearStatus::kNotConverged,
        "CG: relative residual " + std::to_string(r_norm / b_norm) + " after " +
            std::to_string(k) + " iterations (tolerance " + std::to_string(options_.tolerance) +
            ")");
    result.iterations = k;
    result.residual = r_norm / b_norm;
  }
  return result;
}

LinearResult CgSolver::solve(const VecX& b, VecX& x) {
  if (a_ == nullptr)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: solve without a successful factorize");
  if (b.size() != r_.size() || x.size() != r_.size())
    return LinearResult::failure(LinearStatus::kInvalidInput, "CG: solve: wrong vector size");
  ++counters_.solves;
  // With a lagged factor, give up early: a fresh factorization is cheaper than many iterations.
  const int first_limit =
      factor_ && !fresh_ ? std::min(options_.max_iterations, options_.lagged_iteration_limit)
                         : options_.max_iterations;
  LinearResult result = run(b, x, first_limit);
  if (factor_ && !fresh_ && result.status == LinearStatus::kNotConverged) {
    // The lagged factor is too far from A: refactor now and solve again.
    stale_ = true;
    LinearResult f = factorize(*a_);
    if (!f.ok()) return f;
    const int before = result.iterations;
    result = run(b, x, options_.max_iterations);
    result.iterations += before;
  }
  if (factor_ && result.iterations > options_.refactor_iterations) stale_ = true;
  return result;
}

}  // namespace jelly
