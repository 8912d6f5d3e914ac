#include <jelly/core/detail/builtin_forces.hpp>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/model.hpp>

namespace jelly {

void GravityForce::add_forces(Real /*t*/, const VecX& /*x*/, const VecX& /*v*/, VecX& f) const {
  for (int i = 0; i < model_->num_particles(); ++i)
    f.segment<3>(3 * i) += model_->mass[i] * model_->gravity;
}

void SpringForce::add_forces(Real /*t*/, const VecX& x, const VecX& v, VecX& f) const {
  add_spring_forces(*model_, x, v, f);
}

void SpringForce::add_jacobian(Real /*t*/, const VecX& x, const VecX& v, ForceJacobian& j) const {
  JacobianOptions options;
  options.definiteness = DefinitenessFix::kNone;
  options.exact_damper = true;
  const SpringJacobian pattern(*model_);
  SparseMatrix k = pattern.make_matrix(), d = pattern.make_matrix();
  pattern.assemble(*model_, x, v, options, k, d);
  // Block (i, j) of each matrix, read column by column.
  const auto block = [](const SparseMatrix& m, int i, int jj) {
    Mat3 out;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) out(r, c) = m.coeff(3 * i + r, 3 * jj + c);
    return out;
  };
  // K and D hold the sum over the springs in dense 3x3 blocks: each stored block once.
  for (int col = 0; col < k.outerSize(); col += 3) {
    for (SparseMatrix::InnerIterator it(k, col); it; ++it) {
      if (it.row() % 3 != 0) continue;
      const int i = static_cast<int>(it.row()) / 3, jj = col / 3;
      j.add(i, jj, block(k, i, jj), block(d, i, jj));
    }
  }
}

void ExternalForces::add_forces(Real t, const VecX& /*x*/, const VecX& v, VecX& f) const {
  add_external_forces(model_->external_forces, model_->mass, t, v, f);
}

void ExternalForces::add_jacobian(Real t, const VecX& /*x*/, const VecX& /*v*/,
                                  ForceJacobian& j) const {
  VecX damping = VecX::Zero(model_->num_particles());
  add_external_damping(model_->external_forces, t, damping);
  for (int i = 0; i < damping.size(); ++i)
    if (damping[i] != 0) j.add(i, i, Mat3::Zero(), -damping[i] * Mat3::Identity());
}

void AnchorForce::add_forces(Real /*t*/, const VecX& x, const VecX& v, VecX& f) const {
  add_anchor_forces(anchors_, x, v, f);
}

void AnchorForce::add_jacobian(Real /*t*/, const VecX& /*x*/, const VecX& /*v*/,
                               ForceJacobian& j) const {
  for (const AnchorSpring& a : anchors_)
    j.add(a.particle, a.particle, -a.stiffness * Mat3::Identity(), -a.damping * Mat3::Identity());
}

std::vector<std::unique_ptr<Force>> builtin_forces(const Model& model,
                                                   const AnchorSprings& anchors) {
  std::vector<std::unique_ptr<Force>> forces;
  forces.push_back(std::make_unique<GravityForce>(model));
  forces.push_back(std::make_unique<SpringForce>(model));
  forces.push_back(std::make_unique<ExternalForces>(model));
  if (!anchors.empty()) forces.push_back(std::make_unique<AnchorForce>(anchors));
  return forces;
}

}  // namespace jelly
