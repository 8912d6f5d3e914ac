#include <jelly/solvers/linear/detail/smoothed_aggregation.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

namespace {

// Coarsening stops when a level would keep more than this fraction of its finer level's
// unknowns, or after this many levels.
constexpr double kAmgMinReduction = 0.5;
constexpr int kAmgMaxLevels = 12;
// A mode of an aggregate is kept when its Gram eigenvalue exceeds this times the largest.
constexpr Real kAmgModeTolerance = 1e-10;
constexpr int kAmgPowerIterations = 12;
constexpr int kAmgCoarsestUnknowns = 400;
// A diagonal block or coarsest operator that is only semi-definite gets this times its largest
// diagonal entry added to its diagonal.
constexpr Real kAmgShift = 1e-12;
// Rows per thread below which another thread costs more than it saves.
constexpr long kAmgMinRowsPerThread = 2048;
// The largest node of any level (6 near-null modes).
constexpr int kAmgMaxNode = 6;
using NodeMatrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic, 0, kAmgMaxNode, kAmgMaxNode>;

// body(begin, end) over a static split of the rows [0, n).
template <class Body>
void for_rows(int threads, long n, Body&& body) {
  parallel::run(parallel::team_size(threads, n, kAmgMinRowsPerThread), [&](int part, int parts) {
    const parallel::Range range = parallel::split(n, part, parts);
    if (range.begin < range.end) body(range.begin, range.end);
  });
}

}  // namespace

long SmoothedAggregation::non_zeros(int l) const {
  return l == 0 ? static_cast<long>(fine_->nonZeros()) : static_cast<long>(levels_[l].a.nonZeros());
}

SmoothedAggregation::View SmoothedAggregation::view(int l) const {
  View v;
  if (l == 0) {
    v.rows = static_cast<int>(fine_->rows());
    v.ptr = fine_->outerIndexPtr();
    v.col = fine_->innerIndexPtr();
    v.val = fine_->valuePtr();
  } else {
    const RowMatrix& a = levels_[l].a;
    v.rows = static_cast<int>(a.rows());
    v.ptr = a.outerIndexPtr();
    v.col = a.innerIndexPtr();
    v.val = a.valuePtr();
  }
  return v;
}

void SmoothedAggregation::aggregate(int l) {
  Level& level = levels_[l];
  const View a = view(l);
  const int nodes = level.nodes();
  std::vector<int> node_of(a.rows);
  for (int i = 0; i < nodes; ++i)
    for (int r = level.node_start[i]; r < level.node_start[i + 1]; ++r) node_of[r] = i;
  // The node graph: the neighbours of each node, sorted. Level 0: every coupling of the pattern
  // but those of isolated nodes (no strength threshold: the mass often outweighs each spring's
  // block at large steps, and thresholds measured no better); coarse levels: the nonzero
  // blocks.
  std::vector<Real> diagonal(nodes, 0.0);
  std::vector<std::vector<std::pair<int, Real>>> blocks(nodes);
  for (int i = 0; i < nodes; ++i) {
    std::vector<std::pair<int, Real>>& n = blocks[i];
    for (int r = level.node_start[i]; r < level.node_start[i + 1]; ++r)
      for (int q = a.ptr[r]; q < a.ptr[r + 1]; ++q) {
        const int j = node_of[a.col[q]];
        if (j == i) {
          diagonal[i] += a.val[q] * a.val[q];
        } else if (l > 0 || (!isolated_[i] && !isolated_[j])) {
          n.emplace_back(j, a.val[q] * a.val[q]);
        }
      }
    std::sort(n.begin(), n.end());
  }
  std::vector<std::vector<int>> neighbours(nodes);
  for (int i = 0; i < nodes; ++i) {
    const std::vector<std::pair<int, Real>>& n = blocks[i];
    for (size_t k = 0; k < n.size();) {
      size_t e = k;
      Real sum = 0;
      while (e < n.size() && n[e].first == n[k].first) sum += n[e++].second;
      const int j = n[k].first;
      if (sum > 0 || l == 0) neighbours[i].push_back(j);
      k = e;
    }
  }
  std::vector<int>& agg = level.aggregate;
  agg.assign(nodes, -1);
  int count = 0;
  // 1: a node whose neighbours are all free seeds an aggregate of itself and them.
  for (int i = 0; i < nodes; ++i) {
    if (agg[i] >= 0 || neighbours[i].empty()) continue;
    if (std::any_of(neighbours[i].begin(), neighbours[i].end(), [&](int j) { return agg[j] >= 0; }))
      continue;
    agg[i] = count;
    for (int j : neighbours[i]) agg[j] = count;
    ++count;
  }
  // 2: a free node joins the aggregate of its first neighbour in one (of step 1).
  const std::vector<int> seeded = agg;
  for (int i = 0; i < nodes; ++i) {
    if (agg[i] >= 0) continue;
    for (int j : neighbours[i])
      if (seeded[j] >= 0) {
        agg[i] = seeded[j];
        break;
      }
  }
  // 3: the rest form aggregates with their free neighbours; a node without neighbours has none.
  for (int i = 0; i < nodes; ++i) {
    if (agg[i] >= 0 || neighbours[i].empty()) continue;
    agg[i] = count;
    for (int j : neighbours[i])
      if (agg[j] < 0) agg[j] = count;
    ++count;
  }
  level.aggregates = count;
}

void SmoothedAggregation::tentative(int l, const std::vector<Real>& modes, int m,
                                    std::vector<Real>& coarse_modes) {
  Level& level = levels_[l];
  const int nodes = level.nodes();
  std::vector<std::vector<int>> members(level.aggregates);
  for (int i = 0; i < nodes; ++i)
    if (level.aggregate[i] >= 0) members[level.aggregate[i]].push_back(i);
  std::vector<Eigen::Triplet<Real>> triplets;
  level.coarse_start.assign(level.aggregates + 1, 0);
  coarse_modes.clear();
  for (int k = 0; k < level.aggregates; ++k) {
    std::vector<int> rows;
    for (int i : members[k])
      for (int r = level.node_start[i]; r < level.node_start[i + 1]; ++r) rows.push_back(r);
    const int nr = static_cast<int>(rows.size());
    Eigen::MatrixXd b(nr, m);
    for (int q = 0; q < nr; ++q)
      for (int c = 0; c < m; ++c) b(q, c) = modes[static_cast<size_t>(rows[q]) * m + c];
    if (l == 0 && m == 6) {
      // Rotations about the aggregate's centre (the modes hold the coordinates there).
      Vec3 centre = Vec3::Zero();
      for (int q = 0; q < nr; q += 3) centre += b.block<1, 3>(q, 3).transpose();
      centre /= static_cast<Real>(nr / 3);
      for (int q = 0; q < nr; q += 3) {
        const Vec3 p = b.block<1, 3>(q, 3).transpose() - centre;
        b.block<3, 3>(q, 3) << 0, p.z(), -p.y(), -p.z(), 0, p.x(), p.y(), -p.x(), 0;
      }
    }
    // An orthonormal basis of the aggregate's modes: T_k = B V S^-1/2, B = T_k (S^1/2 V^T),
    // keeping the eigenvectors of B^T B whose eigenvalues are not negligible.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(b.transpose() * b);
    const Eigen::VectorXd& s = eig.eigenvalues();  // ascending
    const Real largest = s[m - 1];
    std::vector<int> kept;
    for (int c = m - 1; c >= 0; --c)
      if (s[c] > kAmgModeTolerance * largest && static_cast<int>(kept.size()) < kAmgMaxNode)
        kept.push_back(c);
    const int nk = static_cast<int>(kept.size());
    const int start = level.coarse_start[k];
    level.coarse_start[k + 1] = start + nk;
    for (int c = 0; c < nk; ++c) {
      const Eigen::VectorXd v = eig.eigenvectors().col(kept[c]);
      const Eigen::VectorXd t = b * v / std::sqrt(s[kept[c]]);
      for (int q = 0; q < nr; ++q) triplets.emplace_back(rows[q], start + c, t[q]);
      for (int j = 0; j < m; ++j) coarse_modes.push_back(std::sqrt(s[kept[c]]) * v[j]);
    }
  }
  level.tentative.resize(level.rows(), level.coarse_start.back());
  level.tentative.setFromTriplets(triplets.begin(), triplets.end());
  level.tentative.makeCompressed();
}

LinearResult SmoothedAggregation::invert_diagonal(int l, int threads) {
  Level& level = levels_[l];
  const View a = view(l);
  const int nodes = level.nodes();
  if (level.inverse_start.size() != static_cast<size_t>(nodes) + 1) {
    level.inverse_start.assign(nodes + 1, 0);
    for (int i = 0; i < nodes; ++i) {
      const int k = level.node_start[i + 1] - level.node_start[i];
      level.inverse_start[i + 1] = level.inverse_start[i] + k * k;
    }
    level.inverse.assign(level.inverse_start.back(), 0.0);
  }
  std::vector<long> bad(parallel::team_size(threads, nodes, kAmgMinRowsPerThread / 3), nodes);
  parallel::run(static_cast<int>(bad.size()), [&](int part, int parts) {
    const parallel::Range range = parallel::split(nodes, part, parts);
    for (long i = range.begin; i < range.end; ++i) {
      const int s = level.node_start[i], k = level.node_start[i + 1] - s;
      NodeMatrix d = NodeMatrix::Zero(k, k);
      for (int r = 0; r < k; ++r)
        for (int q = a.ptr[s + r]; q < a.ptr[s + r + 1]; ++q) {
          const int c = a.col[q] - s;
          if (c >= 0 && c < k) d(r, c) = a.val[q];
        }
      NodeMatrix sym = 0.5 * (d + d.transpose());
      Eigen::LLT<NodeMatrix> llt(sym);
      if (llt.info() != Eigen::Success && l > 0) {  // a rank-deficient prolongator's block
        const Real shift = kAmgShift * sym.diagonal().cwiseAbs().maxCoeff();
        sym.diagonal().array() += shift > 0 ? shift : 1.0;
        llt.compute(sym);
      }
      if (llt.info() != Eigen::Success) {
        bad[part] = i;
        return;
      }
      const NodeMatrix inv = llt.solve(NodeMatrix::Identity(k, k));
      Real* out = level.inverse.data() + level.inverse_start[i];
      for (int r = 0; r < k; ++r)
        for (int c = 0; c < k; ++c) out[r * k + c] = 0.5 * (inv(r, c) + inv(c, r));
    }
  });
  const long first_bad = *std::min_element(bad.begin(), bad.end());
  if (first_bad < nodes)
    return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                 "CG: amg: diagonal block " + std::to_string(first_bad + 1) +
                                     " of level " + std::to_string(l) +
                                     " is not positive definite");
  return {};
}

void SmoothedAggregation::multiply(int l, const VecX& x, VecX& y, int threads) const {
  const View a = view(l);
  const Real* px = x.data();
  Real* py = y.data();
  for_rows(threads, a.rows, [&](long begin, long end) {
    for (long r = begin; r < end; ++r) {
      Real s = 0;
      for (int q = a.ptr[r]; q < a.ptr[r + 1]; ++q) s += a.val[q] * px[a.col[q]];
      py[r] = s;
    }
  });
}

void SmoothedAggregation::scale_add(int l, const VecX& res, VecX& out, Real alpha, Real beta,
                                    int threads) const {
  const Level& level = levels_[l];
  const Real* pr = res.data();
  Real* po = out.data();
  for_rows(threads, level.nodes(), [&](long begin, long end) {
    for (long i = begin; i < end; ++i) {
      const int s = level.node_start[i], k = level.node_start[i + 1] - s;
      const Real* inv = level.inverse.data() + level.inverse_start[i];
      for (int r = 0; r < k; ++r) {
        Real sum = 0;
        for (int c = 0; c < k; ++c) sum += inv[r * k + c] * pr[s + c];
        po[s + r] = (alpha == 0 ? 0 : alpha * po[s + r]) + beta * sum;
      }
    }
  });
}

void SmoothedAggregation::residual(int l, const VecX& x, int threads) {
  Level& level = levels_[l];
  multiply(l, x, level.t, threads);
  for_rows(threads, level.rows(), [&](long begin, long end) {
    for (long i = begin; i < end; ++i) level.t[i] = level.b[i] - level.t[i];
  });
}

void SmoothedAggregation::relax(int l, VecX& x, bool from_zero, int threads) {
  Level& level = levels_[l];
  const int degree = l == 0 ? options_.fine_degree : options_.coarse_degree;
  // Chebyshev polynomial in D^-1 A of degree `degree` on [upper / 10, upper].
  const Real upper = level.upper, lower = 0.1 * upper;
  const Real theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower);
  const Real sigma = theta / delta;
  Real rho = 1 / sigma;
  if (from_zero) {
    scale_add(l, level.b, level.d, 0, 1 / theta, threads);
  } else {
    residual(l, x, threads);
    scale_add(l, level.t, level.d, 0, 1 / theta, threads);
  }
  for (int k = 1; k <= degree; ++k) {
    if (k == 1 && from_zero) {
      x = level.d;
    } else {
      for_rows(threads, level.rows(), [&](long begin, long end) {
        for (long i = begin; i < end; ++i) x[i] += level.d[i];
      });
    }
    if (k == degree) break;
    residual(l, x, threads);
    const Real rho_next = 1 / (2 * sigma - rho);
    scale_add(l, level.t, level.d, rho_next * rho, 2 * rho_next / delta, threads);
    rho = rho_next;
  }
}

void SmoothedAggregation::transfer(const RowMatrix& m, const VecX& in, VecX& out, bool add,
                                   int threads) const {
  const int* ptr = m.outerIndexPtr();
  const int* col = m.innerIndexPtr();
  const Real* val = m.valuePtr();
  const Real* pi = in.data();
  Real* po = out.data();
  for_rows(threads, m.rows(), [&](long begin, long end) {
    for (long r = begin; r < end; ++r) {
      Real s = 0;
      for (int q = ptr[r]; q < ptr[r + 1]; ++q) s += val[q] * pi[col[q]];
      po[r] = add ? po[r] + s : s;
    }
  });
}

Real SmoothedAggregation::estimate_lambda(int l, int threads) {
  Level& level = levels_[l];
  const int n = level.rows();
  VecX& x = level.x;
  VecX& y = level.t;
  for (int i = 0; i < n; ++i) x[i] = 1.0 + 0.5 * std::sin(1.0 + i);
  Real lambda = 0;
  for (int k = 0; k < kAmgPowerIterations; ++k) {
    x /= x.norm();
    multiply(l, x, y, threads);
    scale_add(l, y, x, 0, 1, threads);  // x = D^-1 A x
    lambda = x.norm();
  }
  return lambda;
}

LinearResult SmoothedAggregation::setup(const SparseMatrix& a, const VecX& coordinates,
                                        int threads) {
  levels_.clear();
  fine_ = &a;
  const int n = static_cast<int>(a.rows());
  if (n % 3 != 0 || a.rows() != a.cols())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CG: amg: the matrix must be square, of 3x3 blocks");
  const bool rotations = coordinates.size() == n;
  int m = rotations ? 6 : 3;
  // Level 0's modes: the translations, and the coordinates (turned into rotations about each
  // aggregate's centre by tentative()).
  std::vector<Real> modes(static_cast<size_t>(n) * m, 0.0);
  for (int r = 0; r < n; ++r) {
    modes[static_cast<size_t>(r) * m + r % 3] = 1;
    if (rotations)
      for (int d = 0; d < 3; ++d)
        modes[static_cast<size_t>(r) * m + 3 + d] = coordinates[r - r % 3 + d];
  }
  // Nodes without couplings now (pins, sticking contacts) stay out of the coarse space: the
  // smoother solves their rows exactly.
  isolated_.assign(n / 3, 1);
  for (int r = 0; r < n; ++r)
    for (int q = a.outerIndexPtr()[r]; q < a.outerIndexPtr()[r + 1]; ++q)
      if (a.innerIndexPtr()[q] / 3 != r / 3 && a.valuePtr()[q] != 0) isolated_[r / 3] = 0;
  levels_.emplace_back();
  levels_[0].node_start.resize(n / 3 + 1);
  for (int i = 0; i <= n / 3; ++i) levels_[0].node_start[i] = 3 * i;
  // Coarsen while the level is large: aggregates, T and the values of the next level.
  for (int l = 0;; ++l) {
    Level& level = levels_[l];
    level.x.setZero(level.rows());
    level.b.setZero(level.rows());
    level.t.setZero(level.rows());
    level.d.setZero(level.rows());
    if (level.rows() <= kAmgCoarsestUnknowns || l + 1 >= kAmgMaxLevels) break;
    aggregate(l);
    std::vector<Real> coarse_modes;
    tentative(l, modes, m, coarse_modes);
    const int coarse_rows = level.coarse_start.back();
    if (coarse_rows == 0 || coarse_rows > kAmgMinReduction * level.rows()) {
      level.tentative.resize(0, 0);
      break;
    }
    modes.swap(coarse_modes);
    Level next;
    next.node_start = level.coarse_start;
    levels_.push_back(std::move(next));
    // The next level's pattern (for its aggregates) comes with its values.
    const LinearResult r = refresh(a, threads);
    if (!r.ok()) return r;
  }
  return refresh(a, threads);
}

LinearResult SmoothedAggregation::refresh(const SparseMatrix& a, int threads) {
  fine_ = &a;
  const int levels = static_cast<int>(levels_.size());
  for (int l = 0; l < levels; ++l) {
    Level& level = levels_[l];
    LinearResult r = invert_diagonal(l, threads);
    if (!r.ok()) return r;
    const Real lambda = estimate_lambda(l, threads);
    level.upper = 1.1 * lambda;
    if (l == 0) level.upper = std::min(2.0, level.upper);
    if (l + 1 == levels) {
      coarsest_dense_ = level.rows() <= kAmgCoarsestUnknowns;
      if (coarsest_dense_) {
        const View c = view(l);
        Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(c.rows, c.rows);
        for (int row = 0; row < c.rows; ++row)
          for (int q = c.ptr[row]; q < c.ptr[row + 1]; ++q) dense(row, c.col[q]) = c.val[q];
        dense = (0.5 * (dense + dense.transpose())).eval();
        // A coarse operator may be semi-definite (a rank-deficient prolongator): a tiny shift
        // keeps the V-cycle positive definite.
        const Real shift = kAmgShift * dense.diagonal().cwiseAbs().maxCoeff();
        for (int tries = 0; tries < 3; ++tries) {
          coarsest_.compute(dense);
          if (coarsest_.info() == Eigen::Success) break;
          dense.diagonal().array() += shift * std::pow(1e3, tries);
        }
        if (coarsest_.info() != Eigen::Success)
          return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                       "CG: amg: the coarsest level is not positive definite");
      }
      break;
    }
    // P = (I - 4/(3 lambda) D^-1 A) T.
    std::vector<Eigen::Triplet<Real>> d;
    for (int i = 0; i < level.nodes(); ++i) {
      const int s = level.node_start[i], k = level.node_start[i + 1] - s;
      const Real* inv = level.inverse.data() + level.inverse_start[i];
      for (int rr = 0; rr < k; ++rr)
        for (int c = 0; c < k; ++c) d.emplace_back(s + rr, s + c, inv[rr * k + c]);
    }
    RowMatrix dinv(level.rows(), level.rows());
    dinv.setFromTriplets(d.begin(), d.end());
    const View v = view(l);
    const Eigen::Map<const RowMatrix> al(v.rows, v.rows, v.ptr[v.rows], v.ptr, v.col, v.val);
    const RowMatrix at = al * level.tentative;
    RowMatrix smoothing = dinv * at;
    smoothing *= 4.0 / (3.0 * lambda);
    level.p = level.tentative - smoothing;
    level.p.makeCompressed();
    level.r = level.p.transpose();
    level.r.makeCompressed();
    const RowMatrix ap = al * level.p;
    const RowMatrix coarse = level.r * ap;
    const RowMatrix transposed = coarse.transpose();
    Level& next = levels_[l + 1];
    next.a = 0.5 * (coarse + transposed);
    next.a.makeCompressed();
    if (next.x.size() != next.rows()) {
      next.x.setZero(next.rows());
      next.b.setZero(next.rows());
      next.t.setZero(next.rows());
      next.d.setZero(next.rows());
    }
  }
  return {};
}

LinearResult SmoothedAggregation::update_fine(const SparseMatrix& a, int threads) {
  fine_ = &a;
  return invert_diagonal(0, threads);
}

void SmoothedAggregation::cycle(int l, int threads) {
  Level& level = levels_[l];
  const int levels = static_cast<int>(levels_.size());
  if (l + 1 == levels) {
    if (coarsest_dense_) {
      level.x = coarsest_.solve(level.b);
    } else {
      relax(l, level.x, true, threads);
    }
    return;
  }
  Level& next = levels_[l + 1];
  relax(l, level.x, true, threads);
  residual(l, level.x, threads);
  transfer(level.r, level.t, next.b, false, threads);
  cycle(l + 1, threads);
  if (options_.w_cycle && l + 2 < levels && 4 * next.rows() <= level.rows()) {
    // W-cycle below level 1: a second cycle on the coarse residual (the same symmetric
    // operator again: the product stays symmetric positive definite). Only below a level at
    // most a quarter of this one: 2^k visits of level k cost at most (2/4)^k of level 0's.
    next.w = next.x;
    next.s = next.b;
    residual(l + 1, next.x, threads);
    next.b = next.t;
    cycle(l + 1, threads);
    next.x += next.w;
    next.b = next.s;
  }
  transfer(level.p, next.x, level.x, true, threads);
  relax(l, level.x, false, threads);
}

void SmoothedAggregation::apply(const VecX& r, VecX& z, int threads) {
  Level& fine = levels_[0];
  parallel::for_ranges(threads, r.size(), [&](long begin, long end) {
    std::copy(r.data() + begin, r.data() + end, fine.b.data() + begin);
  });
  cycle(0, threads);
  parallel::for_ranges(threads, r.size(), [&](long begin, long end) {
    std::copy(fine.x.data() + begin, fine.x.data() + end, z.data() + begin);
  });
}

}  // namespace jelly
