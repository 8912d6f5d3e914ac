#include <jelly/core/force.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

void ForceJacobian::multiply(const VecX& p, VecX& dfdx_p, VecX& dfdv_p) const {
  for (const Block& b : blocks_) {
    dfdx_p.segment<3>(3 * b.i) += b.dfdx * p.segment<3>(3 * b.j);
    dfdv_p.segment<3>(3 * b.i) += b.dfdv * p.segment<3>(3 * b.j);
  }
}

void ForceJacobian::validate(int num_particles, const std::string& force) const {
  for (const Block& b : blocks_) {
    require(b.i >= 0 && b.i < num_particles && b.j >= 0 && b.j < num_particles,
            "force '" + force + "' Jacobian block",
            "(" + std::to_string(b.i) + ", " + std::to_string(b.j) + ")",
            "particle indices in [0, " + std::to_string(num_particles) + ")");
    require(b.dfdx.allFinite() && b.dfdv.allFinite(), "force '" + force + "' Jacobian block values",
            "(" + std::to_string(b.i) + ", " + std::to_string(b.j) + ")", "finite numbers");
  }
}

namespace {
using MatX = Eigen::MatrixXd;

// Central differences of the force in x (wrt_x) or v, column by column.
MatX difference_jacobian(const Force& force, Real t, const VecX& x, const VecX& v, Real step,
                         bool wrt_x) {
  const Eigen::Index n = x.size();
  MatX j(n, n);
  VecX xp = x, vp = v, fp(n), fm(n);
  VecX& moved = wrt_x ? xp : vp;
  for (Eigen::Index k = 0; k < n; ++k) {
    const Real at = moved[k];
    const Real h = step * std::max<Real>(1, std::abs(at));
    moved[k] = at + h;
    fp.setZero();
    force.add_forces(t, xp, vp, fp);
    moved[k] = at - h;
    fm.setZero();
    force.add_forces(t, xp, vp, fm);
    moved[k] = at;
    j.col(k) = (fp - fm) / (2 * h);
  }
  return j;
}

Real relative_error(const MatX& exact, const MatX& difference) {
  const Real scale = std::max(difference.cwiseAbs().maxCoeff(), exact.cwiseAbs().maxCoeff());
  if (scale == 0) return 0;
  return (exact - difference).cwiseAbs().maxCoeff() / scale;
}
}  // namespace

JacobianCheck check_force_jacobian(const Force& force, Real t, const VecX& x, const VecX& v,
                                   Real step) {
  const Eigen::Index n = x.size();
  MatX dfdx = MatX::Zero(n, n), dfdv = MatX::Zero(n, n);
  if (force.has_jacobian()) {
    ForceJacobian jacobian;
    force.add_jacobian(t, x, v, jacobian);
    for (const ForceJacobian::Block& b : jacobian.blocks()) {
      dfdx.block<3, 3>(3 * b.i, 3 * b.j) += b.dfdx;
      dfdv.block<3, 3>(3 * b.i, 3 * b.j) += b.dfdv;
    }
  }
  JacobianCheck check;
  check.dfdx_error = relative_error(dfdx, difference_jacobian(force, t, x, v, step, true));
  check.dfdv_error = relative_error(dfdv, difference_jacobian(force, t, x, v, step, false));
  check.dfdx_scale = dfdx.cwiseAbs().maxCoeff();
  check.dfdv_scale = dfdv.cwiseAbs().maxCoeff();
  return check;
}

}  // namespace jelly
