#include <jelly/bench/stability_region.hpp>

#include <Eigen/LU>
#include <cmath>
#include <complex>
#include <vector>

#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/dynamics.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::bench {

Eigen::Matrix2d amplification_matrix(const std::string& integrator, Real h, Real w2, Real c) {
  constexpr Real kRest = 1000;
  Model model;
  model.mass = VecX::Constant(2, 2.0);  // reduced mass 1: s'' = -ks s - kd s'
  model.rest_position = VecX::Zero(6);
  model.rest_position[3] = kRest;
  model.springs.add(0, 1, kRest, {w2, c * w2}, SpringType::kStructural);
  model.gravity.setZero();
  const ContactSolver no_contact;
  Eigen::Matrix2d a;
  for (int column = 0; column < 2; ++column) {
    const Real s = column == 0 ? 1.0 : 0.0, u = column == 1 ? 1.0 : 0.0;
    State state;
    state.x = VecX::Zero(6);
    state.v = VecX::Zero(6);
    state.x[0] = -0.5 * (kRest + s);
    state.x[3] = 0.5 * (kRest + s);
    state.v[0] = -0.5 * u;
    state.v[3] = 0.5 * u;
    const Dynamics dynamics(model, no_contact);
    auto method = make_integrator(integrator);
    if (!method->step(dynamics, state, h).ok) {
      a.setConstant(NAN);
      return a;
    }
    a(0, column) = (state.x[3] - state.x[0]) - kRest;
    a(1, column) = state.v[3] - state.v[0];
  }
  return a;
}

Real amplification(const std::string& integrator, Real h, Real w2, Real c) {
  const Eigen::Matrix2d a = amplification_matrix(integrator, h, w2, c);
  if (!a.allFinite()) return INFINITY;
  // Eigenvalues of a 2x2 matrix: (tr +- sqrt(tr^2 - 4 det)) / 2.
  const std::complex<Real> tr = a.trace(), det = a.determinant();
  const std::complex<Real> root = std::sqrt(tr * tr - 4.0 * det);
  return std::max(std::abs(0.5 * (tr + root)), std::abs(0.5 * (tr - root)));
}

Real predicted_max_dt(const std::string& integrator, Real rho, Real c, Real h_cap, Real h_min) {
  constexpr int kSamples = 400;
  std::vector<Real> w2;
  for (int k = 0; k < kSamples; ++k) w2.push_back(rho * std::pow(1e-4, 1.0 - k / (kSamples - 1.0)));
  // Position-based methods (projective_dynamics, xpbd, both implicit) take v1 = (x1 - x0) / h,
  // whose rounding (eps |x| / h with |x| = 500 m here) alone exceeds 1e-9 below h = 1e-4 s: for
  // implicit methods the tolerance allows for it (the explicit ones keep 1e-9, which resolves
  // the weak instability of explicit Euler and midpoint on undamped modes).
  const Real rounding = make_integrator(integrator)->is_implicit() ? 1e-12 : 0.0;
  const auto stable = [&](Real h) {
    for (Real w : w2) {
      if (!(amplification(integrator, h, w, c) <= 1 + 1e-9 + rounding / h)) return false;
    }
    return true;
  };
  if (!stable(h_min)) return 0;
  Real lo = h_min, hi = h_cap;
  for (Real h = h_min * 1.25;; h *= 1.25) {
    if (h >= h_cap) {
      if (stable(h_cap)) return h_cap;
      hi = h_cap;
      break;
    }
    if (!stable(h)) {
      hi = h;
      break;
    }
    lo = h;
  }
  while (hi / lo > 1 + 1e-4) {
    const Real mid = std::sqrt(lo * hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo;
}

bool is_adaptive_integrator(const std::string& integrator) {
  return make_integrator(integrator)->is_adaptive();
}

}  // namespace jelly::bench
