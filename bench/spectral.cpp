#include <jelly/bench/spectral.hpp>

#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

namespace jelly::bench {

namespace {

void product(const Model& model, const std::vector<Real>& coefficient, const VecX& v, VecX& y) {
  const Springs& s = model.springs;
  const VecX& x = model.rest_position;
  y.setZero();
  for (int k = 0; k < s.size(); ++k) {
    const int a = s.a[k], b = s.b[k];
    const Vec3 d = (particle(x, a) - particle(x, b)).normalized();
    // -c d d^T (v_a - v_b) on a, the opposite on b.
    const Vec3 f = -coefficient[k] * d.dot(particle(v, a) - particle(v, b)) * d;
    particle(y, a) += f;
    particle(y, b) -= f;
  }
}

}  // namespace

void stiffness_product(const Model& model, const VecX& v, VecX& y) {
  product(model, model.springs.ks, v, y);
}

void damping_product(const Model& model, const VecX& v, VecX& y) {
  product(model, model.springs.kd, v, y);
}

Real spectral_radius(const Model& model, bool damping, int max_iterations, Real tolerance,
                     int* iterations) {
  const int dim = model.num_dofs();
  const int m_max = std::min(dim, max_iterations);
  // S = 1 / sqrt(m) per degree of freedom; the operator is v -> -S A S v (symmetric, >= 0).
  VecX scale(dim);
  for (int i = 0; i < model.num_particles(); ++i)
    scale.segment<3>(3 * i).setConstant(1.0 / std::sqrt(model.mass[i]));
  const auto apply = [&](const VecX& v, VecX& y) {
    const VecX sv = scale.cwiseProduct(v);
    if (damping) {
      damping_product(model, sv, y);
    } else {
      stiffness_product(model, sv, y);
    }
    y = -scale.cwiseProduct(y);
  };
  // A fixed, deterministic start vector with every component non-zero.
  Eigen::MatrixXd basis(dim, m_max);
  VecX q(dim);
  for (int i = 0; i < dim; ++i) q[i] = 1.0 + 0.5 * std::sin(1.7 * i + 0.3);
  basis.col(0) = q.normalized();
  std::vector<Real> alpha, beta;
  VecX w(dim);
  Real ritz = 0;
  int m = 0;
  for (m = 1; m <= m_max; ++m) {
    apply(basis.col(m - 1), w);
    alpha.push_back(basis.col(m - 1).dot(w));
    // Full reorthogonalisation (twice is enough) against every Lanczos vector so far.
    for (int pass = 0; pass < 2; ++pass) {
      w -= basis.leftCols(m) * (basis.leftCols(m).transpose() * w);
    }
    const Real b = w.norm();
    Eigen::MatrixXd t = Eigen::MatrixXd::Zero(m, m);
    for (int i = 0; i < m; ++i) {
      t(i, i) = alpha[i];
      if (i + 1 < m) t(i, i + 1) = t(i + 1, i) = beta[i];
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(t);
    ritz = solver.eigenvalues()[m - 1];
    // Residual of the top Ritz pair: |beta_m * last component of its eigenvector|.
    const Real residual = std::abs(b * solver.eigenvectors()(m - 1, m - 1));
    if (residual <= tolerance * std::abs(ritz) || m == m_max || b <= 1e-14 * std::abs(ritz)) {
      break;
    }
    beta.push_back(b);
    basis.col(m) = w / b;
  }
  if (iterations) *iterations = std::min(m, m_max);
  return ritz;
}

SpectralEstimate estimate_spectrum(const Model& model) {
  SpectralEstimate e;
  e.rho_k = spectral_radius(model, false, 300, 1e-10, &e.iterations_k);
  e.rho_d = spectral_radius(model, true, 300, 1e-10, &e.iterations_d);
  return e;
}

}  // namespace jelly::bench
