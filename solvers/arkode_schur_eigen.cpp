// The SchurSystem of arkode_dirk on Eigen: the spring Jacobians K, D assembled here and Eigen's
// SimplicialLLT. A fallback written while the shared Jacobian assembly (core/jacobian) and the
// CHOLMOD wrapper were not yet available on this branch.
#include <jelly/solvers/arkode_schur.hpp>

#include <algorithm>
#include <cmath>

#include <Eigen/SparseCholesky>

namespace jelly::arkode {

struct SchurSystem::Factorization {
  Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower> llt;
};

namespace {
// Offset of entry (row, col) in a compressed column-major matrix (the entry must exist).
int offset(const SparseMatrix& m, int row, int col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  return static_cast<int>(std::lower_bound(begin, end, row) - m.innerIndexPtr());
}
}  // namespace

SchurSystem::SchurSystem(const Model& model) : factorization_(std::make_unique<Factorization>()) {
  const int n = model.num_dofs();
  const Springs& springs = model.springs;
  std::vector<Eigen::Triplet<Real>> triplets;
  triplets.reserve(36 * springs.size() + n);
  const auto block = [&](int p, int q) {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) triplets.emplace_back(3 * p + r, 3 * q + c, 0.0);
  };
  for (int i = 0; i < springs.size(); ++i) {
    block(springs.a[i], springs.a[i]);
    block(springs.b[i], springs.b[i]);
    block(springs.a[i], springs.b[i]);
    block(springs.b[i], springs.a[i]);
  }
  for (int j = 0; j < n; ++j) triplets.emplace_back(j, j, 0.0);
  k_.resize(n, n);
  k_.setFromTriplets(triplets.begin(), triplets.end());
  k_.makeCompressed();
  d_ = k_;
  s_ = k_;
  scatter_.resize(36 * static_cast<size_t>(springs.size()));
  for (int i = 0; i < springs.size(); ++i) {
    const int a = springs.a[i], b = springs.b[i];
    const int blocks[4][2] = {{a, a}, {b, b}, {a, b}, {b, a}};
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
          scatter_[36 * i + 9 * k + 3 * c + r] =
              offset(k_, 3 * blocks[k][0] + r, 3 * blocks[k][1] + c);
  }
  diagonal_.resize(n);
  for (int j = 0; j < n; ++j) diagonal_[j] = offset(k_, j, j);
  factorization_->llt.analyzePattern(s_);  // the symbolic analysis, once per pattern
}

SchurSystem::~SchurSystem() = default;

void SchurSystem::assemble(const Model& model, const VecX& x, const VecX& v) {
  (void)v;  // D = df/dv depends on the positions only
  const Springs& springs = model.springs;
  Real* kv = k_.valuePtr();
  Real* dv = d_.valuePtr();
  std::fill(kv, kv + k_.nonZeros(), 0.0);
  std::fill(dv, dv + d_.nonZeros(), 0.0);
  for (int i = 0; i < springs.size(); ++i) {
    const Vec3 e = particle(x, springs.a[i]) - particle(x, springs.b[i]);
    const Real l = e.norm();
    if (!(l > 0)) continue;
    const Vec3 d = e / l;
    const Eigen::Matrix3d dd = d * d.transpose();
    // df_a/dx_a = -ks [d d^T + max(0, 1 - l0/l) (I - d d^T)]; df_a/dv_a = -kd d d^T.
    const Real geometric = std::max(0.0, 1.0 - springs.rest_length[i] / l);
    const Eigen::Matrix3d ks =
        -springs.ks[i] * (dd + geometric * (Eigen::Matrix3d::Identity() - dd));
    const Eigen::Matrix3d kd = -springs.kd[i] * dd;
    const int* at = scatter_.data() + 36 * i;
    for (int k = 0; k < 4; ++k) {
      const Real sign = k < 2 ? 1.0 : -1.0;  // (a, a), (b, b) get +, (a, b), (b, a) get -
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) {
          kv[at[9 * k + 3 * c + r]] += sign * ks(r, c);
          dv[at[9 * k + 3 * c + r]] += sign * kd(r, c);
        }
    }
  }
}

bool SchurSystem::factorize(const Model& model, Real gamma, std::string* why) {
  const Real* kv = k_.valuePtr();
  const Real* dv = d_.valuePtr();
  Real* sv = s_.valuePtr();
  for (Eigen::Index p = 0; p < s_.nonZeros(); ++p) sv[p] = -gamma * dv[p] - gamma * gamma * kv[p];
  for (int j = 0; j < static_cast<int>(diagonal_.size()); ++j)
    sv[diagonal_[j]] += model.mass[j / 3];
  factorization_->llt.factorize(s_);
  if (factorization_->llt.info() == Eigen::Success) return true;
  if (why != nullptr) *why = "M - gamma D - gamma^2 K is not positive definite";
  return false;
}

void SchurSystem::solve(const VecX& r, VecX& out) const { out = factorization_->llt.solve(r); }

}  // namespace jelly::arkode
