#include <jelly/solvers/linear/cg_solver.hpp>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/LU>

namespace jelly {

namespace {

// CPU time of this thread: the lagging decision must not depend on the load of the machine.
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

bool has_block3_pattern(const SparseMatrix& a) {
  if (a.rows() % 3 != 0) return false;
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  for (Eigen::Index j = 0; j < a.cols(); j += 3) {
    const int s = outer[j + 1] - outer[j];
    if (s % 3 != 0 || outer[j + 2] - outer[j + 1] != s || outer[j + 3] - outer[j + 2] != s)
      return false;
    for (int q = 0; q < s; ++q) {
      const int row = inner[outer[j] + q];
      if (inner[outer[j] + s + q] != row || inner[outer[j] + 2 * s + q] != row) return false;
      if (q % 3 != 0 && row != inner[outer[j] + q - 1] + 1) return false;
    }
  }
  return true;
}

}  // namespace

struct CgSolver::Impl {
  explicit Impl(const CgOptions& o) : options_(o) {}

  LinearResult analyze(const SparseMatrix& a, LinearSolverCounters& counters);
  LinearResult factorize(const SparseMatrix& a, LinearSolverCounters& counters);
  LinearResult solve(const VecX& b, VecX& x, LinearSolverCounters& counters);
  LinearResult run(const VecX& b, VecX& x, int max_iterations, LinearSolverCounters& counters);
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

CgSolver::CgSolver(CgOptions options) : impl_(std::make_unique<Impl>(options)) {
  if (options.preconditioner == CgPreconditioner::kLaggedCholesky)
    impl_->factor_ = std::make_unique<CholmodSolver>(options.cholmod);
}

CgSolver::~CgSolver() = default;

std::string_view CgSolver::name() const {
  return impl_->options_.preconditioner == CgPreconditioner::kJacobi ? "cg_jacobi"
                                                                     : "cg_lagged_cholmod";
}

LinearResult CgSolver::analyze(const SparseMatrix& a) { return impl_->analyze(a, counters_); }

LinearResult CgSolver::factorize(const SparseMatrix& a) { return impl_->factorize(a, counters_); }

LinearResult CgSolver::solve(const VecX& b, VecX& x) { return impl_->solve(b, x, counters_); }

void CgSolver::invalidate() { impl_->stale_ = true; }

long CgSolver::preconditioner_factorizations() const {
  return impl_->preconditioner_factorizations_;
}

LinearResult CgSolver::Impl::analyze(const SparseMatrix& a, LinearSolverCounters& counters) {
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
  block3_ = has_block3_pattern(a);
  diagonal_block_.clear();
  if (block3_) {
    const int* outer = a.outerIndexPtr();
    const int* inner = a.innerIndexPtr();
    for (Eigen::Index j = 0; j < n; j += 3) {
      const int* begin = inner + outer[j];
      const int* end = inner + outer[j + 1];
      const int* at = std::lower_bound(begin, end, static_cast<int>(j));
      if (at == end || *at != j) {
        block3_ = false;
        break;
      }
      diagonal_block_.push_back(static_cast<int>(at - inner));
    }
    inverse_blocks_.assign(block3_ ? 3 * static_cast<size_t>(n) : 0, 0.0);
  }
  upper_start_.assign(1, 0);
  upper_row_.clear();
  upper_source_.clear();
  if (block3_) {
    const int* outer = a.outerIndexPtr();
    const int* inner = a.innerIndexPtr();
    for (Eigen::Index j = 0; j < n; j += 3) {
      for (int q = outer[j]; q < outer[j + 1]; q += 3) {
        if (inner[q] > j) break;  // rows are sorted: the rest is below the diagonal
        upper_row_.push_back(inner[q] / 3);
        upper_source_.push_back(q);
      }
      upper_start_.push_back(static_cast<int>(upper_row_.size()));
    }
    upper_values_.assign(9 * upper_row_.size(), 0.0);
  }
  ++counters.analyses;
  if (factor_) {
    LinearResult r = factor_->analyze(a);
    if (!r.ok()) return r;
  }
  return {};
}

LinearResult CgSolver::Impl::factorize(const SparseMatrix& a, LinearSolverCounters& counters) {
  if (a.rows() != r_.size())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: factorize: the matrix does not have the analysed size");
  a_ = &a;
  if (block3_) {
    const int* outer = a.outerIndexPtr();
    const Real* values = a.valuePtr();
    const int blocks_per_row = static_cast<int>(upper_start_.size()) - 1;
    for (int j = 0; j < blocks_per_row; ++j) {
      const int s = outer[3 * j + 1] - outer[3 * j];
      for (int k = upper_start_[j]; k < upper_start_[j + 1]; ++k) {
        const Real* src = values + upper_source_[k];
        Real* dst = &upper_values_[9 * static_cast<size_t>(k)];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) dst[3 * r + c] = src[c * s + r];
      }
    }
  }
  if (!factor_) {
    if (block3_) {
      const int* outer = a.outerIndexPtr();
      const Real* values = a.valuePtr();
      for (size_t i = 0; i < diagonal_block_.size(); ++i) {
        const int base = diagonal_block_[i];
        const int s = outer[3 * i + 1] - outer[3 * i];
        Eigen::Matrix3d block;
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) block(r, c) = values[base + c * s + r];
        Eigen::Matrix3d inverse;
        bool invertible = false;
        block.computeInverseWithCheck(inverse, invertible);
        if (!invertible || !(block(0, 0) > 0 && block(1, 1) > 0 && block(2, 2) > 0)) {
          a_ = nullptr;
          return LinearResult::failure(
              LinearStatus::kNotPositiveDefinite,
              "CG: diagonal block " + std::to_string(i + 1) + " is not positive definite");
        }
        std::copy(inverse.data(), inverse.data() + 9, &inverse_blocks_[9 * i]);
      }
      return {};
    }
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      const Real d = a.coeff(j, j);
      if (!(d > 0)) {
        a_ = nullptr;
        return LinearResult::failure(
            LinearStatus::kNotPositiveDefinite,
            "CG: diagonal entry " + std::to_string(j + 1) + " is not positive");
      }
      inverse_diagonal_[j] = 1.0 / d;
    }
    return {};
  }
  fresh_ = false;
  if (stale_ || !factor_->factorized()) {
    const double start = thread_seconds();
    LinearResult r = factor_->factorize(a);
    ++counters.factorizations;
    ++preconditioner_factorizations_;
    if (!r.ok()) {
      a_ = nullptr;
      return r;
    }
    factor_seconds_ = thread_seconds() - start;
    lagged_seconds_ = factor_seconds_;
    lagged_solves_ = 0;
    stale_ = false;
    fresh_ = true;
  }
  return {};
}

void CgSolver::Impl::multiply(const VecX& x, VecX& y) const {
  if (!block3_) {
    y.noalias() = *a_ * x;
    return;
  }
  // Upper block triangle only: block (i, j), i < j, adds B x_j to y_i and B^T x_i to y_j.
  const Real* px = x.data();
  Real* py = y.data();
  y.setZero();
  const int blocks_per_row = static_cast<int>(upper_start_.size()) - 1;
  const Real* b = upper_values_.data();
  for (int j = 0; j < blocks_per_row; ++j) {
    const Real xj0 = px[3 * j], xj1 = px[3 * j + 1], xj2 = px[3 * j + 2];
    Real yj0 = 0, yj1 = 0, yj2 = 0;
    const int end = upper_start_[j + 1];
    for (int k = upper_start_[j]; k < end; ++k, b += 9) {
      const int i = upper_row_[k];
      if (i == j) {
        yj0 += b[0] * xj0 + b[1] * xj1 + b[2] * xj2;
        yj1 += b[3] * xj0 + b[4] * xj1 + b[5] * xj2;
        yj2 += b[6] * xj0 + b[7] * xj1 + b[8] * xj2;
        continue;
      }
      Real* yi = py + 3 * i;
      const Real* xi = px + 3 * i;
      yi[0] += b[0] * xj0 + b[1] * xj1 + b[2] * xj2;
      yi[1] += b[3] * xj0 + b[4] * xj1 + b[5] * xj2;
      yi[2] += b[6] * xj0 + b[7] * xj1 + b[8] * xj2;
      yj0 += b[0] * xi[0] + b[3] * xi[1] + b[6] * xi[2];
      yj1 += b[1] * xi[0] + b[4] * xi[1] + b[7] * xi[2];
      yj2 += b[2] * xi[0] + b[5] * xi[1] + b[8] * xi[2];
    }
    py[3 * j] += yj0;
    py[3 * j + 1] += yj1;
    py[3 * j + 2] += yj2;
  }
}

void CgSolver::Impl::precondition(const VecX& r, VecX& z) {
  if (factor_) {
    factor_->solve(r, z);
  } else if (block3_) {
    const Real* pr = r.data();
    Real* pz = z.data();
    const Real* inv = inverse_blocks_.data();
    const Eigen::Index n = r.size();
    for (Eigen::Index i = 0; i < n; i += 3, inv += 9) {
      // Column-major 3x3 inverse times r_i.
      pz[i] = inv[0] * pr[i] + inv[3] * pr[i + 1] + inv[6] * pr[i + 2];
      pz[i + 1] = inv[1] * pr[i] + inv[4] * pr[i + 1] + inv[7] * pr[i + 2];
      pz[i + 2] = inv[2] * pr[i] + inv[5] * pr[i + 1] + inv[8] * pr[i + 2];
    }
  } else {
    z = inverse_diagonal_.cwiseProduct(r);
  }
}

LinearResult CgSolver::Impl::run(const VecX& b, VecX& x, int max_iterations,
                                 LinearSolverCounters& counters) {
  const Real b_norm = b.norm();
  LinearResult result;
  if (b_norm == 0) {
    x.setZero();
    return result;
  }
  multiply(x, q_);
  r_ = b - q_;
  Real r_norm = r_.norm();
  const Real target = options_.tolerance * b_norm;
  int k = 0;
  if (r_norm > target) {
    precondition(r_, z_);
    p_ = z_;
    Real rz = r_.dot(z_);
    while (k < max_iterations) {
      multiply(p_, q_);
      const Real curvature = p_.dot(q_);
      if (!(curvature > 0)) {
        result = LinearResult::failure(
            LinearStatus::kNotPositiveDefinite,
            "CG: non-positive curvature p^T A p = " + std::to_string(curvature) + " at iteration " +
                std::to_string(k + 1) + ": matrix not positive definite");
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
  counters.cg_iterations += k;
  result.iterations = k;
  result.residual = r_norm / b_norm;
  if (result.ok() && !(r_norm <= target)) {
    result = LinearResult::failure(LinearStatus::kNotConverged,
                                   "CG: relative residual " + std::to_string(r_norm / b_norm) +
                                       " after " + std::to_string(k) + " iterations (tolerance " +
                                       std::to_string(options_.tolerance) + ")");
    result.iterations = k;
    result.residual = r_norm / b_norm;
  }
  return result;
}

LinearResult CgSolver::Impl::solve(const VecX& b, VecX& x, LinearSolverCounters& counters) {
  if (a_ == nullptr)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: solve without a successful factorize");
  if (b.size() != r_.size() || x.size() != r_.size())
    return LinearResult::failure(LinearStatus::kInvalidInput, "CG: solve: wrong vector size");
  ++counters.solves;
  const double start = factor_ ? thread_seconds() : 0;
  // With a lagged factor, give up early: a fresh factorization is cheaper than many iterations.
  const int first_limit = factor_ && !fresh_
                              ? std::min(options_.max_iterations, options_.lagged_iteration_limit)
                              : options_.max_iterations;
  LinearResult result = run(b, x, first_limit, counters);
  if (factor_ && !fresh_ && result.status == LinearStatus::kNotConverged) {
    // The lagged factor is too far from A: refactor now and solve again.
    stale_ = true;
    LinearResult f = factorize(*a_, counters);
    if (!f.ok()) return f;
    const int before = result.iterations;
    result = run(b, x, options_.max_iterations, counters);
    result.iterations += before;
  }
  if (factor_) {
    // Keep the factor while this solve costs less than the average per solve since the refresh
    // (factorization included): refreshing then minimises the average cost per step.
    const double cost = thread_seconds() - start;
    lagged_seconds_ += cost;
    ++lagged_solves_;
    if (cost * static_cast<double>(lagged_solves_) > lagged_seconds_ ||
        result.iterations > options_.refactor_iterations)
      stale_ = true;
  }
  return result;
}

}  // namespace jelly
