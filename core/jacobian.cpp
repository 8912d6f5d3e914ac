#include <jelly/core/detail/jacobian.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

namespace {

// The 3x3 blocks of one spring: kb = df_a/dxa and db = df_a/dva (row-major 3x3 arrays).
// With d = xa - xb, L = |d|, u = d / L, w = va - vb, c = w.u, P = I - u u^T:
//   f_a     = -ks (L - l0) u - kd c u
//   df_a/dd = -ks u u^T - ks (1 - l0/L) P - kd (c/L) P - kd/L u (P w)^T
//   df_a/dw = -kd u u^T
// and df_a/dxb = -df_a/dxa, df_b/dxa = -df_a/dxa, df_b/dxb = df_a/dxa (same for v).
struct SpringBlocks {
  Real k[9];
  Real d[9];
};

inline void spring_blocks(const Real* px, const Real* pv, const Real* pr, int ia, int ib, Real rest,
                          Real ks, Real kd, const JacobianOptions& options, SpringBlocks& out) {
  Real dx[3] = {px[ia] - px[ib], px[ia + 1] - px[ib + 1], px[ia + 2] - px[ib + 2]};
  const Real w[3] = {pv[ia] - pv[ib], pv[ia + 1] - pv[ib + 1], pv[ia + 2] - pv[ib + 2]};
  Real length = std::sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
  if (!(length > kDegenerateLength * rest)) {
    // Coincident particles: the direction of the rest positions, as in compute_forces.
    for (int c = 0; c < 3; ++c) dx[c] = pr[ia + c] - pr[ib + c];
    const Real scale =
        kDegenerateLength * rest / std::sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
    for (Real& c : dx) c *= scale;
    length = kDegenerateLength * rest;
  }
  const Real inv = 1.0 / length;
  const Real u[3] = {dx[0] * inv, dx[1] * inv, dx[2] * inv};
  const Real c = w[0] * u[0] + w[1] * u[1] + w[2] * u[2];
  Real spring_geometric = ks * (1 - rest * inv);
  Real damper_geometric = kd * c * inv;
  Real s;
  switch (options.definiteness) {
    case DefinitenessFix::kClampCompressed:
      s = std::max<Real>(spring_geometric, 0) + std::max<Real>(damper_geometric, 0);
      break;
    case DefinitenessFix::kProjectPsd:
      s = std::max<Real>(spring_geometric + damper_geometric, 0);
      break;
    default:
      s = spring_geometric + damper_geometric;
      break;
  }
  // -(ks u u^T + s P) = -(ks - s) u u^T - s I.
  const Real along = ks - s;
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) {
      const Real uu = u[r] * u[col];
      out.k[3 * r + col] = -along * uu - (r == col ? s : 0);
      out.d[3 * r + col] = -kd * uu;
    }
  }
  if (options.exact_damper) {
    // -kd/L u (P w)^T, P w = w - c u.
    const Real pw[3] = {w[0] - c * u[0], w[1] - c * u[1], w[2] - c * u[2]};
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) out.k[3 * r + col] -= kd * inv * u[r] * pw[col];
  }
}

}  // namespace

void spring_jacobian_blocks(const Model& model, const VecX& x, const VecX& v,
                            const JacobianOptions& options, std::vector<Real>& k_blocks,
                            std::vector<Real>& d_blocks) {
  const Springs& s = model.springs;
  k_blocks.resize(9 * static_cast<size_t>(s.size()));
  d_blocks.resize(k_blocks.size());
  SpringBlocks blocks;
  for (int sp = 0; sp < s.size(); ++sp) {
    spring_blocks(x.data(), v.data(), model.rest_position.data(), 3 * s.a[sp], 3 * s.b[sp],
                  s.rest_length[sp], s.ks[sp], s.kd[sp], options, blocks);
    std::copy(blocks.k, blocks.k + 9, &k_blocks[9 * static_cast<size_t>(sp)]);
    std::copy(blocks.d, blocks.d + 9, &d_blocks[9 * static_cast<size_t>(sp)]);
  }
}

// Column particles per thread below which another thread costs more than it saves (each has
// about 30 springs at the seed lattice's 26 neighbours).
constexpr long kMinColumnsPerThread = 256;

SpringJacobian::SpringJacobian(const Model& model,
                               const std::vector<std::pair<int, int>>& extra_blocks)
    : num_particles_(model.num_particles()), num_springs_(model.springs.size()) {
  const Springs& s = model.springs;
  const int n = num_particles_;
  for (int k = 0; k < s.size(); ++k) {
    require(s.a[k] >= 0 && s.a[k] < n && s.b[k] >= 0 && s.b[k] < n && s.a[k] != s.b[k],
            "springs.a/b", std::to_string(s.a[k]) + ", " + std::to_string(s.b[k]),
            "two different particle indices in [0, N)");
  }
  for (const auto& [i, j] : extra_blocks) {
    require(i >= 0 && i < n && j >= 0 && j < n && i != j, "extra_blocks",
            std::to_string(i) + ", " + std::to_string(j),
            "two different particle indices in [0, N)");
  }
  // Adjacency (other particle, spring or -1) of every particle, by counting sort on the
  // particle and then sorted per particle by (other particle, spring).
  adjacency_start_.assign(n + 1, 0);
  for (int k = 0; k < s.size(); ++k) {
    ++adjacency_start_[s.a[k] + 1];
    ++adjacency_start_[s.b[k] + 1];
  }
  for (const auto& [i, j] : extra_blocks) {
    ++adjacency_start_[i + 1];
    ++adjacency_start_[j + 1];
  }
  for (int j = 0; j < n; ++j) adjacency_start_[j + 1] += adjacency_start_[j];
  neighbour_.resize(adjacency_start_.back());
  spring_.resize(neighbour_.size());
  {
    std::vector<int> fill(adjacency_start_.begin(), adjacency_start_.end() - 1);
    const auto add = [&](int i, int j, int k) {
      int e = fill[i]++;
      neighbour_[e] = j;
      spring_[e] = k;
      e = fill[j]++;
      neighbour_[e] = i;
      spring_[e] = k;
    };
    for (int k = 0; k < s.size(); ++k) add(s.a[k], s.b[k], k);
    for (const auto& [i, j] : extra_blocks) add(i, j, -1);
  }
  std::vector<std::pair<int, int>> pairs;
  column_stride_.resize(n);
  self_slot_.resize(n);
  for (int j = 0; j < n; ++j) {
    const int begin = adjacency_start_[j], end = adjacency_start_[j + 1];
    pairs.clear();
    for (int e = begin; e < end; ++e) pairs.emplace_back(neighbour_[e], spring_[e]);
    std::sort(pairs.begin(), pairs.end());
    int distinct = 0, below = 0;
    for (size_t q = 0; q < pairs.size(); ++q) {
      neighbour_[begin + q] = pairs[q].first;
      spring_[begin + q] = pairs[q].second;
      if (q == 0 || pairs[q].first != pairs[q - 1].first) {
        ++distinct;
        if (pairs[q].first < j) ++below;
      }
    }
    column_stride_[j] = 3 * (distinct + 1);
    self_slot_[j] = below;
  }
  // Column 3j + c holds rows 3i, 3i + 1, 3i + 2 of every neighbour i of j and of j, in order.
  col_start_.assign(3 * static_cast<size_t>(n) + 1, 0);
  for (int j = 0; j < n; ++j) {
    for (int c = 0; c < 3; ++c)
      col_start_[3 * j + c + 1] = col_start_[3 * j + c] + column_stride_[j];
  }
  diagonal_.resize(3 * static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    for (int c = 0; c < 3; ++c)
      diagonal_[3 * j + c] = col_start_[3 * j + c] + 3 * self_slot_[j] + c;
  }
}

SparseMatrix SpringJacobian::make_matrix() const {
  const int n = rows();
  SparseMatrix m(n, n);
  m.resizeNonZeros(non_zeros());
  std::copy(col_start_.begin(), col_start_.end(), m.outerIndexPtr());
  int* rows_out = m.innerIndexPtr();
  for (int j = 0; j < num_particles_; ++j) {
    const int begin = adjacency_start_[j], end = adjacency_start_[j + 1];
    for (int c = 0; c < 3; ++c) {
      int at = col_start_[3 * j + c];
      bool self_done = false;
      for (int e = begin; e <= end; ++e) {
        if (e < end && e > begin && neighbour_[e] == neighbour_[e - 1]) continue;
        const int i = e < end ? neighbour_[e] : num_particles_;
        if (!self_done && j < i) {
          for (int r = 0; r < 3; ++r) rows_out[at++] = 3 * j + r;
          self_done = true;
        }
        if (e == end) break;
        for (int r = 0; r < 3; ++r) rows_out[at++] = 3 * i + r;
      }
    }
  }
  std::fill(m.valuePtr(), m.valuePtr() + non_zeros(), 0.0);
  return m;
}

bool SpringJacobian::matches(const SparseMatrix& m) const {
  return m.rows() == rows() && m.cols() == rows() && m.isCompressed() &&
         m.nonZeros() == non_zeros();
}

template <class Spring, class Block>
void SpringJacobian::for_column_springs(int j, Spring&& spring, Block&& block) const {
  const int end = adjacency_start_[j + 1];
  int e = adjacency_start_[j];
  const int blocks = column_stride_[j] / 3;
  for (int slot = 0; slot < blocks; ++slot) {
    if (slot == self_slot_[j]) continue;
    const int i = neighbour_[e];
    for (; e < end && neighbour_[e] == i; ++e) {
      if (spring_[e] >= 0) spring(i, spring_[e]);  // an extra block has none: zero
    }
    block(slot);
  }
}

template <class Column>
void SpringJacobian::for_columns(int threads, Column&& column) const {
  const int team = parallel::team_size(threads, num_particles_, kMinColumnsPerThread);
  parallel::run(team, [&](int part, int parts) {
    const parallel::Range r = parallel::split(num_particles_, part, parts);
    for (long j = r.begin; j < r.end; ++j) column(static_cast<int>(j));
  });
}

namespace {

// Writes the row-major 3x3 block `b` into slot `slot` of the three columns starting at `col`.
inline void write_block(Real* col, int stride, int slot, const Real* b) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) col[c * stride + 3 * slot + r] = b[3 * r + c];
}

}  // namespace

void SpringJacobian::assemble(const Model& model, const VecX& x, const VecX& v,
                              const JacobianOptions& options, SparseMatrix& k, SparseMatrix& d,
                              int threads) const {
  require(matches(k) && matches(d), "jacobian.matrix", k.rows(),
          "matrices made by this SpringJacobian's make_matrix()");
  Real* kv = k.valuePtr();
  Real* dv = d.valuePtr();
  const Springs& s = model.springs;
  const Real* px = x.data();
  const Real* pv = v.data();
  const Real* pr = model.rest_position.data();
  // Column j, row block i (spring k = (j, i)): df_i/dx_j = -K_k; the diagonal block sums K_k.
  for_columns(threads, [&](int j) {
    const int stride = column_stride_[j];
    Real* kcol = kv + col_start_[3 * j];
    Real* dcol = dv + col_start_[3 * j];
    Real kdiag[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    Real ddiag[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    Real koff[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    Real doff[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    SpringBlocks sb;
    for_column_springs(
        j,
        [&](int i, int sp) {
          spring_blocks(px, pv, pr, 3 * j, 3 * i, s.rest_length[sp], s.ks[sp], s.kd[sp], options,
                        sb);
          for (int q = 0; q < 9; ++q) {
            koff[q] -= sb.k[q];
            doff[q] -= sb.d[q];
            kdiag[q] += sb.k[q];
            ddiag[q] += sb.d[q];
          }
        },
        [&](int slot) {
          write_block(kcol, stride, slot, koff);
          write_block(dcol, stride, slot, doff);
          std::fill(koff, koff + 9, 0.0);
          std::fill(doff, doff + 9, 0.0);
        });
    write_block(kcol, stride, self_slot_[j], kdiag);
    write_block(dcol, stride, self_slot_[j], ddiag);
  });
}

void SpringJacobian::assemble_system(const Model& model, const VecX& x, const VecX& v,
                                     const JacobianOptions& options, Real alpha, Real beta,
                                     SparseMatrix& a_matrix, const VecX& w, VecX& kw,
                                     int threads) const {
  require(matches(a_matrix), "jacobian.matrix", a_matrix.rows(),
          "a matrix made by this SpringJacobian's make_matrix()");
  require(!options.exact_damper, "jacobian.exact_damper", "true",
          "false for the (symmetric) system matrix");
  require(kw.size() == rows() && w.size() == rows(), "jacobian.kw", kw.size(),
          "vectors of 3N entries");
  Real* av = a_matrix.valuePtr();
  const Real* m = model.mass.data();
  const Springs& s = model.springs;
  const Real* px = x.data();
  const Real* pv = v.data();
  const Real* pr = model.rest_position.data();
  const Real* pw = w.data();
  Real* pkw = kw.data();
  // Column j: the block of spring k = (j, i) from j's side, ab = -alpha D_k - beta K_k, is
  // added to the diagonal block and subtracted at row block i; (K w)_j = sum K_k (w_j - w_i).
  for_columns(threads, [&](int j) {
    const int stride = column_stride_[j];
    Real* col = av + col_start_[3 * j];
    const Real mj = m[j];
    Real diag[9] = {mj, 0, 0, 0, mj, 0, 0, 0, mj};
    Real kwj[3] = {0, 0, 0};
    const Real* wj = pw + 3 * j;
    Real off[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    SpringBlocks sb;
    for_column_springs(
        j,
        [&](int i, int sp) {
          const Real* wi = pw + 3 * i;
          const Real dw[3] = {wj[0] - wi[0], wj[1] - wi[1], wj[2] - wi[2]};
          spring_blocks(px, pv, pr, 3 * j, 3 * i, s.rest_length[sp], s.ks[sp], s.kd[sp], options,
                        sb);
          for (int r = 0; r < 3; ++r)
            kwj[r] += sb.k[3 * r] * dw[0] + sb.k[3 * r + 1] * dw[1] + sb.k[3 * r + 2] * dw[2];
          for (int q = 0; q < 9; ++q) {
            const Real ab = -alpha * sb.d[q] - beta * sb.k[q];
            off[q] -= ab;
            diag[q] += ab;
          }
        },
        [&](int slot) {
          write_block(col, stride, slot, off);
          std::fill(off, off + 9, 0.0);
        });
    write_block(col, stride, self_slot_[j], diag);
    pkw[3 * j] = kwj[0];
    pkw[3 * j + 1] = kwj[1];
    pkw[3 * j + 2] = kwj[2];
  });
}

}  // namespace jelly
