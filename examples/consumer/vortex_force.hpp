#pragma once
// A force of one's own: a vortex about a vertical axis that swirls particles around it and
// pulls them in. It gives its Jacobians, so implicit_euler takes it into its solve.
#include <Eigen/Geometry>
#include <string>

#include <jelly/jelly.hpp>

// On particle i at x (r = x - centre, projected on the horizontal plane):
//   f_i = m_i (swirl * (axis x r) - pull * r)
// linear in x, so df_i/dx_i = m_i (swirl [axis]x - pull P) with P the horizontal projection.
class VortexForce final : public jelly::Force {
 public:
  VortexForce(const jelly::Model& model, Eigen::Vector3d centre, double swirl, double pull)
      : mass_(model.mass), centre_(centre), swirl_(swirl), pull_(pull) {}

  std::string name() const override { return "vortex"; }

  void add_forces(double /*t*/, const Eigen::VectorXd& x, const Eigen::VectorXd& /*v*/,
                  Eigen::VectorXd& f) const override {
    for (int i = 0; i < mass_.size(); ++i) {
      Eigen::Vector3d r = x.segment<3>(3 * i) - centre_;
      r.y() = 0;
      f.segment<3>(3 * i) += mass_[i] * (swirl_ * kAxis.cross(r) - pull_ * r);
    }
  }

  bool has_jacobian() const override { return true; }

  void add_jacobian(double /*t*/, const Eigen::VectorXd& /*x*/, const Eigen::VectorXd& /*v*/,
                    jelly::ForceJacobian& jacobian) const override {
    Eigen::Matrix3d cross;  // [axis]x: cross * r = axis x r
    cross << 0, -kAxis.z(), kAxis.y(), kAxis.z(), 0, -kAxis.x(), -kAxis.y(), kAxis.x(), 0;
    const Eigen::Matrix3d horizontal = Eigen::Vector3d(1, 0, 1).asDiagonal();
    for (int i = 0; i < mass_.size(); ++i) {
      jacobian.add(i, i, mass_[i] * (swirl_ * cross - pull_ * horizontal) * horizontal,
                   Eigen::Matrix3d::Zero());
    }
  }

 private:
  inline static const Eigen::Vector3d kAxis = Eigen::Vector3d::UnitY();
  Eigen::VectorXd mass_;
  Eigen::Vector3d centre_;
  double swirl_, pull_;
};
