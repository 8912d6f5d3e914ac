#include <jelly/solvers/linear/detail/cg_solver.hpp>

#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/LU>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/solvers/linear/detail/smoothed_aggregation.hpp>

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

// The vectors of CG and its threaded vector operations.
struct CgWork {
  int threads = 1;
  std::vector<Real> partials;
  VecX r, z, p, q;
  // Where the last solve stopped converged, for resuming it (MatrixFreeCg; CgSolver never
  // resumes): |b|, |r|, and when it has a search direction (block Jacobi), r^T z of that
  // direction and of the new residual (the direction not yet updated with it). Cleared by a
  // new size or preconditioner.
  struct Stop {
    bool resumable = false, has_direction = false;
    Real b_norm = 0, r_norm = 0, rz = 0, rz_next = 0;
  } stop;

  void resize(Eigen::Index n) {
    if (r.size() == n) return;
    stop = {};
    r.setZero(n);
    z.setZero(n);
    p.setZero(n);
    q.setZero(n);
  }
  // The sums below run over fixed chunks of kChunk entries (whole particles), added in chunk
  // order. Small enough that two threads get equal shares at n = 20 (24,000 entries: 16 chunks;
  // chunks of 8,192 gave one thread 1 and the other 2 of 3), large enough that a chunk's partial
  // sum costs nothing beside its loop.
  static constexpr long kChunk = 3 * 512;
  // Sum of f(begin, end) over the chunks of [0, n).
  template <class ChunkSum>
  Real sum(ChunkSum&& f) {
    return parallel::ordered_sum(threads, r.size(), partials, f, kChunk);
  }
  // The two sums of f(begin, end) -> {a, b} over the chunks.
  std::vector<Real> pair_partials;
  template <class ChunkSums>
  std::array<Real, 2> sum2(ChunkSums&& f) {
    return parallel::ordered_sums<2>(threads, r.size(), kChunk, pair_partials, f);
  }
  // body(begin, end) over a static split of [0, n) (boundaries multiples of 3).
  template <class Body>
  void for_entries(Body&& body) {
    const long n = r.size();
    parallel::run(parallel::team_size(threads, n), [&](int part, int parts) {
      const parallel::Range range = parallel::split(n, part, parts, 3);
      if (range.begin < range.end) body(range.begin, range.end);
    });
  }
};

// Particles (3x3 blocks) per thread below which another thread costs more than it saves.
constexpr long kMinBlocksPerThread = 1024;

// Block Jacobi: the inverses of A's 3x3 diagonal blocks, symmetric, 6 floats per block (xx, yy,
// zz, xy, xz, yz): a preconditioner only has to be a fixed symmetric positive definite matrix,
// and 24 bytes per particle instead of 72 are read per iteration (docs/implicit.md).
struct BlockInverses {
  std::vector<float> inverse;
  std::vector<long> bad;  // per thread: its first singular or indefinite block

  // Inverts block(i, B) (B the Eigen matrix the callback fills) for i in [0, np) on a static
  // split; a block that is singular or has a non-positive diagonal entry is a failure naming
  // the first one.
  template <class Block>
  LinearResult invert(long np, int threads, Block&& block) {
    if (inverse.size() != 6 * static_cast<size_t>(np)) inverse.assign(6 * np, 0.0f);
    bad.assign(parallel::team_size(threads, np, kMinBlocksPerThread), np);
    parallel::run(static_cast<int>(bad.size()), [&](int part, int parts) {
      const parallel::Range range = parallel::split(np, part, parts);
      for (long i = range.begin; i < range.end; ++i) {
        Eigen::Matrix3d b;
        block(i, b);
        Eigen::Matrix3d inv;
        bool invertible = false;
        b.computeInverseWithCheck(inv, invertible);
        if (!invertible || !(b(0, 0) > 0 && b(1, 1) > 0 && b(2, 2) > 0)) {
          bad[part] = i;
          return;
        }
        float* out = &inverse[6 * i];
        out[0] = static_cast<float>(inv(0, 0));
        out[1] = static_cast<float>(inv(1, 1));
        out[2] = static_cast<float>(inv(2, 2));
        out[3] = static_cast<float>(0.5 * (inv(0, 1) + inv(1, 0)));
        out[4] = static_cast<float>(0.5 * (inv(0, 2) + inv(2, 0)));
        out[5] = static_cast<float>(0.5 * (inv(1, 2) + inv(2, 1)));
      }
    });
    const long first_bad = *std::min_element(bad.begin(), bad.end());
    if (first_bad < np)
      return LinearResult::failure(
          LinearStatus::kNotPositiveDefinite,
          "CG: diagonal block " + std::to_string(first_bad + 1) + " is not positive definite");
    return {};
  }

  // z_i = P_i r_i for the particles of the entries [begin, end) (multiples of 3).
  void apply_range(const Real* r, Real* z, long begin, long end) const {
    const float* inv = inverse.data() + 2 * begin;
    for (long i = begin; i < end; i += 3, inv += 6) {
      const Real r0 = r[i], r1 = r[i + 1], r2 = r[i + 2];
      z[i] = Real{inv[0]} * r0 + Real{inv[3]} * r1 + Real{inv[4]} * r2;
      z[i + 1] = Real{inv[3]} * r0 + Real{inv[1]} * r1 + Real{inv[5]} * r2;
      z[i + 2] = Real{inv[4]} * r0 + Real{inv[5]} * r1 + Real{inv[2]} * r2;
    }
  }

  // z = (block diagonal of the inverses) r, on work's split of the entries.
  void apply(CgWork& work, const VecX& r, VecX& z) const {
    const Real* pr = r.data();
    Real* pz = z.data();
    work.for_entries([&](long begin, long end) { apply_range(pr, pz, begin, end); });
  }

  // One pass for CG's update: x += alpha p, r -= alpha q, z = P r; returns r.r and r.z, summed
  // in fixed chunks of whole particles in chunk order (the same bits for any thread count).
  std::array<Real, 2> update(CgWork& work, Real alpha, const Real* p, const Real* q, Real* x,
                             Real* r, Real* z) const {
    return work.sum2([&](long begin, long end) {
      Real rr = 0, rz = 0;
      for (long i = begin; i < end; ++i) {
        x[i] += alpha * p[i];
        r[i] -= alpha * q[i];
      }
      apply_range(r, z, begin, end);
      for (long i = begin; i < end; ++i) {
        rr += r[i] * r[i];
        rz += r[i] * z[i];
      }
      return std::array<Real, 2>{rr, rz};
    });
  }
};

// Preconditioned CG from x on A x = b; every vector operation on a static split and every sum in
// fixed chunks: the iterates are the same bits for any number of threads.
template <class Apply, class Precondition>
LinearResult cg_run(CgWork& work, Real tolerance, Apply&& multiply, Precondition&& precondition,
                    const VecX& b, VecX& x, int max_iterations, LinearSolverCounters& counters,
                    const BlockInverses* blocks = nullptr, bool resume = false) {
  VecX& r_ = work.r;
  VecX& z_ = work.z;
  VecX& p_ = work.p;
  VecX& q_ = work.q;
  const auto sum = [&work](auto&& f) { return work.sum(f); };
  const auto for_entries = [&work](auto&& f) { work.for_entries(f); };
  // Every vector operation on a static split and every sum in fixed chunks: the iterates are
  // the same bits for any number of threads.
  const Real* pb = b.data();
  Real* px = x.data();
  Real* pr = r_.data();
  Real* pz = z_.data();
  Real* pp = p_.data();
  Real* pq = q_.data();
  CgWork::Stop& stop = work.stop;
  LinearResult result;
  if (resume && !stop.resumable)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: resume without a solve that stopped converged");
  const CgWork::Stop resumed = stop;  // kept when a resume has nothing to do
  stop.resumable = false;
  Real b_norm, r_norm;
  if (resume) {
    b_norm = stop.b_norm;
    r_norm = stop.r_norm;
    if (b_norm == 0) {  // x = 0 solved it
      stop = resumed;
      return result;
    }
  } else {
    b_norm = std::sqrt(sum([&](long begin, long end) {
      Real s = 0;
      for (long i = begin; i < end; ++i) s += pb[i] * pb[i];
      return s;
    }));
    if (b_norm == 0) {
      x.setZero();
      stop = {true, false, 0, 0, 0, 0};
      return result;
    }
    multiply(x, q_);
    r_norm = std::sqrt(sum([&](long begin, long end) {
      Real s = 0;
      for (long i = begin; i < end; ++i) {
        pr[i] = pb[i] - pq[i];
        s += pr[i] * pr[i];
      }
      return s;
    }));
  }
  const Real target = tolerance * b_norm;
  const auto dot = [&](const Real* u, const Real* w) {
    return sum([&](long begin, long end) {
      Real s = 0;
      for (long i = begin; i < end; ++i) s += u[i] * w[i];
      return s;
    });
  };
  int k = 0;
  // The next direction from the residual's r^T z (the end of an iteration).
  const auto next_direction = [&](Real& rz, Real rz_next) {
    const Real beta = rz_next / rz;
    rz = rz_next;
    for_entries([&](long begin, long end) {
      for (long i = begin; i < end; ++i) pp[i] = pz[i] + beta * pp[i];
    });
  };
  if (r_norm > target) {
    Real rz;
    if (resume && stop.has_direction) {  // end the iteration the stop left, as one solve would
      rz = stop.rz;
      if (!(stop.rz_next > 0))
        return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                     "CG: r^T P r = " + std::to_string(stop.rz_next) +
                                         " on resuming: block-Jacobi preconditioner not positive "
                                         "definite");
      next_direction(rz, stop.rz_next);
    } else {
      precondition(r_, z_);
      for_entries([&](long begin, long end) { std::copy(pz + begin, pz + end, pp + begin); });
      rz = dot(pr, pz);
    }
    while (k < max_iterations) {
      multiply(p_, q_);
      const Real curvature = dot(pp, pq);
      if (!(curvature > 0)) {
        result = LinearResult::failure(
            LinearStatus::kNotPositiveDefinite,
            "CG: non-positive curvature p^T A p = " + std::to_string(curvature) + " at iteration " +
                std::to_string(k + 1) + ": matrix not positive definite");
        break;
      }
      const Real alpha = rz / curvature;
      if (blocks != nullptr) {  // block Jacobi: the update, z and both sums in one pass
        const std::array<Real, 2> sums = blocks->update(work, alpha, pp, pq, px, pr, pz);
        const Real rz_next = sums[1];
        r_norm = std::sqrt(sums[0]);
        ++k;
        if (r_norm <= target) {
          stop = {true, true, b_norm, r_norm, rz, rz_next};
          break;
        }
        if (!std::isfinite(r_norm)) break;
        if (!(rz_next > 0)) {  // r^T P r: the rounded preconditioner is not positive definite
          result = LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                         "CG: r^T P r = " + std::to_string(rz_next) +
                                             " at iteration " + std::to_string(k) +
                                             ": block-Jacobi preconditioner not positive definite");
          break;
        }
        next_direction(rz, rz_next);
        continue;
      }
      r_norm = std::sqrt(sum([&](long begin, long end) {
        Real s = 0;
        for (long i = begin; i < end; ++i) {
          px[i] += alpha * pp[i];
          pr[i] -= alpha * pq[i];
          s += pr[i] * pr[i];
        }
        return s;
      }));
      ++k;
      if (r_norm <= target || !std::isfinite(r_norm)) break;
      precondition(r_, z_);
      next_direction(rz, dot(pr, pz));
    }
  }
  if (resume && k == 0 && result.ok()) {
    stop = resumed;  // nothing done: the same stop, direction included
  } else if (result.ok() && r_norm <= target && !stop.resumable) {
    stop = {true, false, b_norm, r_norm, 0, 0};
  }
  counters.cg_iterations += k;
  result.iterations = k;
  result.residual = r_norm / b_norm;
  if (result.ok() && !(r_norm <= target)) {
    result = LinearResult::failure(LinearStatus::kNotConverged,
                                   "CG: relative residual " + std::to_string(r_norm / b_norm) +
                                       " after " + std::to_string(k) + " iterations (tolerance " +
                                       std::to_string(tolerance) + ")");
    result.iterations = k;
    result.residual = r_norm / b_norm;
  }
  return result;
}

struct CgSolver::Impl {
  explicit Impl(const CgOptions& o) : options_(o) {}

  LinearResult analyze(const SparseMatrix& a, LinearSolverCounters& counters);
  LinearResult factorize(const SparseMatrix& a, LinearSolverCounters& counters);
  LinearResult solve(const VecX& b, VecX& x, LinearSolverCounters& counters);
  LinearResult run(const VecX& b, VecX& x, int max_iterations, LinearSolverCounters& counters);
  void precondition(const VecX& r, VecX& z);
  void multiply(const VecX& x, VecX& y);  // y = A x

  bool block3_ = false;  // columns 3j, 3j + 1, 3j + 2 share one row pattern (3x3 blocks)
  std::vector<int> diagonal_block_;  // [N]: value index of diagonal block (0, 0), when block3_
  BlockInverses blocks_;             // when block3_
  double factor_seconds_ = 0;        // CPU time of the last refresh of the lagged factor
  double lagged_seconds_ = 0;        // ... plus the CPU time of the solves since
  long lagged_solves_ = 0;           // solves since the last refresh

  CgOptions options_;
  int threads_ = 1;
  const SparseMatrix* a_ = nullptr;
  VecX inverse_diagonal_;
  CgWork work_;
  std::unique_ptr<CholmodSolver> factor_;
  std::unique_ptr<SmoothedAggregation> amg_;  // kAmg
  VecX coordinates_;                          // kAmg: the near-null space's positions
  bool stale_ = true;                         // the next factorize must refactor
  bool fresh_ = false;                        // the factor is of the current matrix
  long preconditioner_factorizations_ = 0;
};

CgSolver::CgSolver(CgOptions options) : impl_(std::make_unique<Impl>(options)) {
  if (options.preconditioner == CgPreconditioner::kLaggedCholesky)
    impl_->factor_ = std::make_unique<CholmodSolver>(options.cholmod);
  if (options.preconditioner == CgPreconditioner::kAmg)
    impl_->amg_ = std::make_unique<SmoothedAggregation>(SmoothedAggregation::Options{
        options.amg_fine_degree, options.amg_coarse_degree, options.amg_w_cycle});
}

CgSolver::~CgSolver() = default;

std::string_view CgSolver::name() const {
  switch (impl_->options_.preconditioner) {
    case CgPreconditioner::kJacobi:
      return "cg_jacobi";
    case CgPreconditioner::kLaggedCholesky:
      return "cg_lagged_cholmod";
    case CgPreconditioner::kAmg:
      return "cg_amg";
  }
  return "cg";
}

void CgSolver::set_coordinates(const VecX& x) { impl_->coordinates_ = x; }

bool CgSolver::needs_coordinates() const { return impl_->amg_ && !impl_->amg_->ready(); }

int CgSolver::multigrid_levels() const { return impl_->amg_ ? impl_->amg_->levels() : 0; }

LinearResult CgSolver::analyze(const SparseMatrix& a) { return impl_->analyze(a, counters_); }

LinearResult CgSolver::factorize(const SparseMatrix& a) { return impl_->factorize(a, counters_); }

LinearResult CgSolver::solve(const VecX& b, VecX& x) { return impl_->solve(b, x, counters_); }

void CgSolver::invalidate() { impl_->stale_ = true; }

void CgSolver::set_threads(int threads) { impl_->threads_ = std::max(1, threads); }

long CgSolver::preconditioner_factorizations() const {
  return impl_->preconditioner_factorizations_;
}

LinearResult CgSolver::Impl::analyze(const SparseMatrix& a, LinearSolverCounters& counters) {
  if (a.rows() != a.cols() || !a.isCompressed())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: the matrix must be square and compressed");
  const Eigen::Index n = a.rows();
  inverse_diagonal_.setZero(n);
  work_.r.resize(0);
  work_.resize(n);
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
  }
  ++counters.analyses;
  if (amg_) amg_->clear();  // a new pattern: new aggregates
  if (factor_) {
    LinearResult r = factor_->analyze(a);
    if (!r.ok()) return r;
  }
  return {};
}

LinearResult CgSolver::Impl::factorize(const SparseMatrix& a, LinearSolverCounters& counters) {
  if (a.rows() != work_.r.size())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: factorize: the matrix does not have the analysed size");
  a_ = &a;
  if (amg_) {
    if (!block3_) {
      a_ = nullptr;
      return LinearResult::failure(LinearStatus::kInvalidInput,
                                   "CG: the amg preconditioner needs a matrix of 3x3 blocks");
    }
    LinearResult r;
    if (!amg_->ready()) {
      r = amg_->setup(a, coordinates_, threads_);
    } else if (stale_) {
      r = amg_->refresh(a, threads_);
    } else {
      r = amg_->update_fine(a, threads_);
    }
    if (!r.ok()) {
      amg_->clear();
      a_ = nullptr;
      return r;
    }
    if (stale_) ++preconditioner_factorizations_;  // built or refreshed
    stale_ = false;
    return {};
  }
  if (!factor_) {
    if (block3_) {
      const int* outer = a.outerIndexPtr();
      const Real* values = a.valuePtr();
      const long np = static_cast<long>(diagonal_block_.size());
      const LinearResult r = blocks_.invert(np, threads_, [&](long i, Eigen::Matrix3d& block) {
        const int base = diagonal_block_[i];
        const int s = outer[3 * i + 1] - outer[3 * i];
        for (int c = 0; c < 3; ++c)
          for (int row = 0; row < 3; ++row) block(row, c) = values[base + c * s + row];
      });
      if (!r.ok()) {
        a_ = nullptr;
        return r;
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

void CgSolver::Impl::multiply(const VecX& x, VecX& y) {
  if (!block3_) {
    y.noalias() = *a_ * x;
    return;
  }
  // A is symmetric: y_j = (column block j)^T x, a gather per particle j over the rows of its
  // three columns (one row pattern), written by one thread: the same bits for any split.
  const int* outer = a_->outerIndexPtr();
  const int* inner = a_->innerIndexPtr();
  const Real* values = a_->valuePtr();
  const Real* px = x.data();
  Real* py = y.data();
  const long np = static_cast<long>(diagonal_block_.size());
  parallel::run(parallel::team_size(threads_, np, kMinBlocksPerThread), [&](int part, int parts) {
    const parallel::Range range = parallel::split(np, part, parts);
    for (long j = range.begin; j < range.end; ++j) {
      const int begin = outer[3 * j], s = outer[3 * j + 1] - begin;
      const int* rows = inner + begin;
      const Real* c0 = values + begin;
      const Real* c1 = c0 + s;
      const Real* c2 = c1 + s;
      Real y0 = 0, y1 = 0, y2 = 0;
      for (int q = 0; q < s; ++q) {
        const Real xi = px[rows[q]];
        y0 += c0[q] * xi;
        y1 += c1[q] * xi;
        y2 += c2[q] * xi;
      }
      py[3 * j] = y0;
      py[3 * j + 1] = y1;
      py[3 * j + 2] = y2;
    }
  });
}

void CgSolver::Impl::precondition(const VecX& r, VecX& z) {
  if (amg_) {
    amg_->apply(r, z, threads_);
  } else if (factor_) {
    factor_->solve(r, z);
  } else if (block3_) {
    work_.threads = threads_;
    blocks_.apply(work_, r, z);
  } else {
    z = inverse_diagonal_.cwiseProduct(r);
  }
}

LinearResult CgSolver::Impl::run(const VecX& b, VecX& x, int max_iterations,
                                 LinearSolverCounters& counters) {
  work_.threads = threads_;
  return cg_run(
      work_, options_.tolerance, [this](const VecX& in, VecX& out) { multiply(in, out); },
      [this](const VecX& in, VecX& out) { precondition(in, out); }, b, x, max_iterations, counters,
      !factor_ && !amg_ && block3_ ? &blocks_ : nullptr);
}

LinearResult CgSolver::Impl::solve(const VecX& b, VecX& x, LinearSolverCounters& counters) {
  if (a_ == nullptr)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: solve without a successful factorize");
  if (b.size() != work_.r.size() || x.size() != work_.r.size())
    return LinearResult::failure(LinearStatus::kInvalidInput, "CG: solve: wrong vector size");
  ++counters.solves;
  const double start = factor_ ? thread_seconds() : 0;
  // With a lagged factor, give up early: a fresh factorization is cheaper than many iterations.
  const int first_limit = factor_ && !fresh_
                              ? std::min(options_.max_iterations, options_.lagged_iteration_limit)
                              : options_.max_iterations;
  LinearResult result = run(b, x, first_limit, counters);
  // Amg: refresh the coarse levels when they no longer pay (an iteration count: the same
  // decisions on any machine and thread count).
  if (amg_ && result.iterations > options_.refactor_iterations) stale_ = true;
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

struct MatrixFreeCg::Impl {
  CgWork work;
  BlockInverses blocks;
  LinearSolverCounters counters;
};

MatrixFreeCg::MatrixFreeCg() : impl_(std::make_unique<Impl>()) {}
MatrixFreeCg::~MatrixFreeCg() = default;

const LinearSolverCounters& MatrixFreeCg::counters() const { return impl_->counters; }

LinearResult MatrixFreeCg::set_diagonal_blocks(int particles, const DiagonalBlock& block,
                                               int threads) {
  impl_->work.stop = {};  // a new preconditioner: the last solve cannot be resumed
  return impl_->blocks.invert(particles, std::max(1, threads), [&](long i, Eigen::Matrix3d& b) {
    Real d[9];
    block(static_cast<int>(i), d);
    b = Eigen::Map<const Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>(d);
  });
}

LinearResult MatrixFreeCg::solve(const Product& apply, const VecX& b, VecX& x, Real tolerance,
                                 int max_iterations, int threads, bool resume) {
  CgWork& work = impl_->work;
  const BlockInverses& blocks = impl_->blocks;
  if (b.size() % 3 != 0 || x.size() != b.size() ||
      blocks.inverse.size() != 2 * static_cast<size_t>(b.size()))
    return LinearResult::failure(LinearStatus::kInvalidInput, "CG: solve: wrong vector size");
  work.resize(b.size());
  work.threads = std::max(1, threads);
  ++impl_->counters.solves;
  const auto precondition = [&](const VecX& r, VecX& z) { blocks.apply(work, r, z); };
  return cg_run(work, tolerance, apply, precondition, b, x, max_iterations, impl_->counters,
                &blocks, resume);
}

LinearResult MatrixFreeCg::solve(const Product& apply, const Preconditioner& precondition,
                                 const VecX& b, VecX& x, Real tolerance, int max_iterations,
                                 int threads, bool resume) {
  CgWork& work = impl_->work;
  if (b.size() % 3 != 0 || x.size() != b.size())
    return LinearResult::failure(LinearStatus::kInvalidInput, "CG: solve: wrong vector size");
  work.resize(b.size());
  work.threads = std::max(1, threads);
  ++impl_->counters.solves;
  if (!resume) work.stop = {};
  return cg_run(work, tolerance, apply, precondition, b, x, max_iterations, impl_->counters,
                nullptr, resume);
}

}  // namespace jelly
