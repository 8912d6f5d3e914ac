#include <jelly/solvers/adjoint/detail/newton_backward.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include <jelly/core/detail/forces.hpp>

namespace jelly {

MatrixFreeNewtonBackward::MatrixFreeNewtonBackward(const Model& model, bool single_precision)
    : bands_(model),
      band_(bands_, model.num_particles(), single_precision),
      num_particles_(model.num_particles()) {
  const Springs& s = model.springs;
  ends_.resize(2 * static_cast<size_t>(s.size()));
  for (int sp = 0; sp < s.size(); ++sp) {
    ends_[2 * static_cast<size_t>(sp)] = s.a[sp];
    ends_[2 * static_cast<size_t>(sp) + 1] = s.b[sp];
  }
  terms_.assign(6 * static_cast<size_t>(s.size()), 0.0);
  inverse_.assign(9 * static_cast<size_t>(num_particles_), 0.0);
}

bool MatrixFreeNewtonBackward::assemble(const Model& model, const VecX& x1, const VecX& v1, Real h,
                                        int threads) {
  // The symmetric part: the forward's band system at (x1, v1) without the definiteness fix.
  scratch_.resize(x1.size());
  if (!band_.assemble(model, x1, v1, DefinitenessFix::kNone, h, h * h, v1, scratch_, threads))
    return false;
  // The dampers' non-symmetric part of -h^2 K: E = h^2 kd / L u (P w)^T at (a, a) and (b, b),
  // -E at (a, b) and (b, a), so that (J^T p)_a += q (u . (p_a - p_b)), q = h^2 kd / L P w.
  const Springs& s = model.springs;
  for (int sp = 0; sp < s.size(); ++sp) {
    const Vec3 d = particle(x1, s.a[sp]) - particle(x1, s.b[sp]);
    const Real length = d.norm();
    const Vec3 u = d / length;
    const Vec3 w = particle(v1, s.a[sp]) - particle(v1, s.b[sp]);
    const Vec3 q = (h * h * s.kd[sp] / length) * (w - w.dot(u) * u);
    for (int c = 0; c < 3; ++c) {
      terms_[6 * static_cast<size_t>(sp) + c] = u[c];
      terms_[6 * static_cast<size_t>(sp) + 3 + c] = q[c];
    }
  }
  return true;
}

void MatrixFreeNewtonBackward::add_damper_transposed(const VecX& p, VecX& y) const {
  // (p and y are distinct vectors: restrict lets the loads of one spring overlap the stores of
  // the last.)
  const Real* __restrict pp = p.data();
  Real* __restrict yp = y.data();
  const Real* __restrict terms = terms_.data();
  const int* __restrict ends = ends_.data();
  const size_t count = ends_.size() / 2;
  for (size_t sp = 0; sp < count; ++sp) {
    const Real* u = terms + 6 * sp;
    const Real* q = u + 3;
    const size_t a = 3 * static_cast<size_t>(ends[2 * sp]);
    const size_t b = 3 * static_cast<size_t>(ends[2 * sp + 1]);
    const Real t =
        u[0] * (pp[a] - pp[b]) + u[1] * (pp[a + 1] - pp[b + 1]) + u[2] * (pp[a + 2] - pp[b + 2]);
    for (int c = 0; c < 3; ++c) {
      yp[a + c] += q[c] * t;
      yp[b + c] -= q[c] * t;
    }
  }
}

void MatrixFreeNewtonBackward::multiply_transposed(const VecX& p, VecX& y, int threads) const {
  band_.multiply(p, y, threads);
  add_damper_transposed(p, y);
}

void MatrixFreeNewtonBackward::apply(const VecX& p, VecX& y, int threads) const {
  // F^T = S J^T S + C + I - S at the constrained particles: the band product filters its input
  // and output itself; the dampers' part takes S p and its constrained rows are projected.
  band_.multiply(p, y, threads, filter_);
  if (filter_.slot == nullptr) {
    add_damper_transposed(p, y);
    return;
  }
  filtered_input_ = p;
  for (int i = 0; i < num_particles_; ++i) {
    if (filter_.slot[i] < 0) continue;
    const Eigen::Map<const Eigen::Matrix3d> s(filter_.map +
                                              9 * static_cast<size_t>(filter_.slot[i]));
    particle(filtered_input_, i) = s * particle(p, i);
  }
  scratch_.setZero(p.size());
  add_damper_transposed(filtered_input_, scratch_);
  for (int i = 0; i < num_particles_; ++i) {
    if (filter_.slot[i] < 0) {
      particle(y, i) += particle(scratch_, i);
    } else {
      const Eigen::Map<const Eigen::Matrix3d> s(filter_.map +
                                                9 * static_cast<size_t>(filter_.slot[i]));
      particle(y, i) += s * particle(scratch_, i);
    }
  }
}

void MatrixFreeNewtonBackward::precondition(const VecX& r, VecX& z) const {
  for (int i = 0; i < num_particles_; ++i) {
    const Eigen::Map<const Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>> inv(
        &inverse_[9 * static_cast<size_t>(i)]);
    particle(z, i) = inv * particle(r, i);
  }
}

LinearResult MatrixFreeNewtonBackward::solve(const VecX& b, VecX& mu, const ProductFilter& filter,
                                             Real tolerance, int max_iterations, int threads) {
  filter_ = filter;
  const int np = num_particles_;
  const Eigen::Index n = b.size();
  // Block Jacobi: F^T's diagonal blocks, the symmetric band's plus sum q u^T of the particle's
  // springs, filtered at the constrained particles (S B S + c S + I - S).
  for (int i = 0; i < np; ++i) {
    Real d[9];
    band_.diagonal_block(i, d);
    std::copy(d, d + 9, &inverse_[9 * static_cast<size_t>(i)]);
  }
  for (size_t sp = 0; sp < ends_.size() / 2; ++sp) {
    const Real* u = &terms_[6 * sp];
    const Real* q = u + 3;
    for (const int i : {ends_[2 * sp], ends_[2 * sp + 1]}) {
      Real* d = &inverse_[9 * static_cast<size_t>(i)];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) d[3 * r + c] += q[r] * u[c];
    }
  }
  for (int i = 0; i < np; ++i) {
    Eigen::Map<Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>> block(
        &inverse_[9 * static_cast<size_t>(i)]);
    Eigen::Matrix3d m = block;
    if (filter_.slot != nullptr && filter_.slot[i] >= 0) {
      const size_t at = static_cast<size_t>(filter_.slot[i]);
      const Eigen::Map<const Eigen::Matrix3d> s(filter_.map + 9 * at);
      const Real c = filter_.scale != nullptr ? filter_.scale[at] : 0.0;
      m = s * m * s + c * s + Eigen::Matrix3d::Identity() - s;
    }
    Eigen::Matrix3d inv;
    bool invertible = false;
    m.computeInverseWithCheck(inv, invertible);
    if (!invertible)
      return LinearResult::failure(
          LinearStatus::kFailure,
          "BiCGSTAB: diagonal block " + std::to_string(i + 1) + " is singular");
    block = inv;
  }
  // Preconditioned BiCGSTAB (van der Vorst), the preconditioner on the right.
  for (VecX* w : {&r_, &r0_, &p_, &v_, &s_, &t_, &y_, &z_}) w->resize(n);
  const Real b_norm = b.norm();
  LinearResult out;
  if (!(b_norm > 0)) {
    mu.setZero(n);
    return out;
  }
  const Real threshold = tolerance * tolerance * b_norm * b_norm;
  apply(mu, v_, threads);
  r_ = b - v_;
  r0_ = r_;
  Real rho = 1, alpha = 1, omega = 1;
  p_.setZero();
  v_.setZero();
  const Real eps2 = std::numeric_limits<Real>::epsilon() * std::numeric_limits<Real>::epsilon();
  for (int it = 0;; ++it) {
    const Real r2 = r_.squaredNorm();
    if (r2 <= threshold) {
      out.iterations = it;
      out.residual = std::sqrt(r2) / b_norm;
      return out;
    }
    if (it >= max_iterations || !std::isfinite(r2)) {
      out.status = LinearStatus::kNotConverged;
      out.iterations = it;
      out.residual = std::sqrt(r2) / b_norm;
      out.message = "BiCGSTAB did not reach cg_tolerance in cg_max_iterations (relative residual " +
                    std::to_string(out.residual) + ")";
      return out;
    }
    const Real rho_old = rho;
    rho = r0_.dot(r_);
    // r0 nearly orthogonal to r, or a stagnated step (omega = 0): restart from r.
    if (std::abs(rho) < eps2 * r0_.squaredNorm() || omega == 0) {
      r0_ = r_;
      rho = r2;
      p_.setZero();
      v_.setZero();
      alpha = omega = 1;
    }
    const Real beta = (rho / rho_old) * (alpha / omega);
    p_ = r_ + beta * (p_ - omega * v_);
    precondition(p_, y_);
    apply(y_, v_, threads);
    alpha = rho / r0_.dot(v_);
    s_ = r_ - alpha * v_;
    if (s_.squaredNorm() <= threshold) {
      mu += alpha * y_;
      r_ = s_;
      continue;
    }
    precondition(s_, z_);
    apply(z_, t_, threads);
    const Real tt = t_.squaredNorm();
    omega = tt > 0 ? t_.dot(s_) / tt : 0.0;
    mu += alpha * y_ + omega * z_;
    r_ = s_ - omega * t_;
  }
}

}  // namespace jelly
