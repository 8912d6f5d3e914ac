#include <jelly/core/detail/jacobian.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/forces.hpp>

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

SpringJacobian::SpringJacobian(const Model& model) : num_particles_(model.num_particles()) {
  const Springs& s = model.springs;
  const int n = num_particles_;
  for (int k = 0; k < s.size(); ++k) {
    require(s.a[k] >= 0 && s.a[k] < n && s.b[k] >= 0 && s.b[k] < n && s.a[k] != s.b[k],
            "springs.a/b", std::to_string(s.a[k]) + ", " + std::to_string(s.b[k]),
            "two different particle indices in [0, N)");
  }
  // Neighbour lists (incl. the particle itself) of every particle, sorted and unique.
  std::vector<std::vector<int>> neighbours(n);
  for (int i = 0; i < n; ++i) neighbours[i].push_back(i);
  for (int k = 0; k < s.size(); ++k) {
    neighbours[s.a[k]].push_back(s.b[k]);
    neighbours[s.b[k]].push_back(s.a[k]);
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  // Column 3j + c holds rows 3i, 3i + 1, 3i + 2 of every neighbour i of j, in order.
  col_start_.assign(3 * n + 1, 0);
  column_stride_.resize(n);
  for (int j = 0; j < n; ++j) {
    column_stride_[j] = 3 * static_cast<int>(neighbours[j].size());
    for (int c = 0; c < 3; ++c)
      col_start_[3 * j + c + 1] = col_start_[3 * j + c] + column_stride_[j];
  }
  row_index_.resize(col_start_.back());
  diagonal_.resize(3 * n);
  for (int j = 0; j < n; ++j) {
    for (int c = 0; c < 3; ++c) {
      int at = col_start_[3 * j + c];
      for (int i : neighbours[j]) {
        for (int r = 0; r < 3; ++r) {
          if (i == j && r == c) diagonal_[3 * j + c] = at;
          row_index_[at++] = 3 * i + r;
        }
      }
    }
  }
  // Value index of entry (0, 0) of block (row particle i, column particle j).
  const auto block = [&](int i, int j) {
    const auto& list = neighbours[j];
    const int pos = static_cast<int>(std::lower_bound(list.begin(), list.end(), i) - list.begin());
    return col_start_[3 * j] + 3 * pos;
  };
  spring_base_.resize(4 * static_cast<size_t>(s.size()));
  for (int k = 0; k < s.size(); ++k) {
    const int a = s.a[k], b = s.b[k];
    spring_base_[4 * k] = block(a, a);
    spring_base_[4 * k + 1] = block(a, b);
    spring_base_[4 * k + 2] = block(b, a);
    spring_base_[4 * k + 3] = block(b, b);
  }
}

SparseMatrix SpringJacobian::make_matrix() const {
  const int n = rows();
  SparseMatrix m(n, n);
  m.resizeNonZeros(non_zeros());
  std::copy(col_start_.begin(), col_start_.end(), m.outerIndexPtr());
  std::copy(row_index_.begin(), row_index_.end(), m.innerIndexPtr());
  std::fill(m.valuePtr(), m.valuePtr() + non_zeros(), 0.0);
  return m;
}

bool SpringJacobian::matches(const SparseMatrix& m) const {
  return m.rows() == rows() && m.cols() == rows() && m.isCompressed() &&
         m.nonZeros() == non_zeros();
}

void SpringJacobian::assemble(const Model& model, const VecX& x, const VecX& v,
                              const JacobianOptions& options, SparseMatrix& k,
                              SparseMatrix& d) const {
  require(matches(k) && matches(d), "jacobian.matrix", k.rows(),
          "matrices made by this SpringJacobian's make_matrix()");
  Real* kv = k.valuePtr();
  Real* dv = d.valuePtr();
  std::fill(kv, kv + non_zeros(), 0.0);
  std::fill(dv, dv + non_zeros(), 0.0);
  const Springs& s = model.springs;
  SpringBlocks blocks;
  for (int sp = 0; sp < s.size(); ++sp) {
    const int a = s.a[sp], b = s.b[sp];
    spring_blocks(x.data(), v.data(), model.rest_position.data(), 3 * a, 3 * b, s.rest_length[sp],
                  s.ks[sp], s.kd[sp], options, blocks);
    const int* base = &spring_base_[4 * sp];
    const int stride[4] = {column_stride_[a], column_stride_[b], column_stride_[a],
                           column_stride_[b]};
    const Real sign[4] = {1, -1, -1, 1};
    for (int q = 0; q < 4; ++q) {
      for (int c = 0; c < 3; ++c) {
        const int at = base[q] + c * stride[q];
        for (int r = 0; r < 3; ++r) {
          kv[at + r] += sign[q] * blocks.k[3 * r + c];
          dv[at + r] += sign[q] * blocks.d[3 * r + c];
        }
      }
    }
  }
}

void SpringJacobian::assemble_system(const Model& model, const VecX& x, const VecX& v,
                                     const JacobianOptions& options, Real alpha, Real beta,
                                     SparseMatrix& a_matrix, const VecX& w, VecX& kw) const {
  require(matches(a_matrix), "jacobian.matrix", a_matrix.rows(),
          "a matrix made by this SpringJacobian's make_matrix()");
  require(!options.exact_damper, "jacobian.exact_damper", "true",
          "false for the (symmetric) system matrix");
  Real* av = a_matrix.valuePtr();
  std::fill(av, av + non_zeros(), 0.0);
  kw.setZero();
  const Real* m = model.mass.data();
  for (int i = 0; i < rows(); ++i) av[diagonal_[i]] = m[i / 3];
  const Springs& s = model.springs;
  const Real* pw = w.data();
  Real* pkw = kw.data();
  SpringBlocks blocks;
  Real ab[9];
  for (int sp = 0; sp < s.size(); ++sp) {
    const int a = s.a[sp], b = s.b[sp];
    const int ia = 3 * a, ib = 3 * b;
    spring_blocks(x.data(), v.data(), model.rest_position.data(), ia, ib, s.rest_length[sp],
                  s.ks[sp], s.kd[sp], options, blocks);
    // Block of A = -alpha D - beta K; kw_a += K (wa - wb), kw_b -= K (wa - wb).
    const Real dw[3] = {pw[ia] - pw[ib], pw[ia + 1] - pw[ib + 1], pw[ia + 2] - pw[ib + 2]};
    for (int r = 0; r < 3; ++r) {
      const Real kdw =
          blocks.k[3 * r] * dw[0] + blocks.k[3 * r + 1] * dw[1] + blocks.k[3 * r + 2] * dw[2];
      pkw[ia + r] += kdw;
      pkw[ib + r] -= kdw;
    }
    for (int e = 0; e < 9; ++e) ab[e] = -alpha * blocks.d[e] - beta * blocks.k[e];
    const int* base = &spring_base_[4 * sp];
    const int sa = column_stride_[a], sb = column_stride_[b];
    for (int c = 0; c < 3; ++c) {
      Real* aa = av + base[0] + c * sa;
      Real* abk = av + base[1] + c * sb;
      Real* ba = av + base[2] + c * sa;
      Real* bb = av + base[3] + c * sb;
      for (int r = 0; r < 3; ++r) {
        const Real e = ab[3 * r + c];
        aa[r] += e;
        abk[r] -= e;
        ba[r] -= e;
        bb[r] += e;
      }
    }
  }
}

}  // namespace jelly
