#pragma once
// Forces as plugins: a Force adds its forces at (t, x, v) at every force evaluation of every
// integrator, and may give its Jacobians df/dx and df/dv as 3x3 blocks, which implicit_euler
// takes into its solve. A user's force and jelly's own (core/detail/builtin_forces.hpp) are peers.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

using Mat3 = Eigen::Matrix3d;  // a 3x3 block of a Jacobian

// The Jacobians of a force as 3x3 blocks: block (i, j) holds d f_i / d x_j and d f_i / d v_j
// (i, j particle indices). Blocks may repeat; repeated blocks add up.
class ForceJacobian {
 public:
  // One 3x3 block (i, j) of df/dx and df/dv.
  struct Block {
    int i = 0;                 // the particle whose force it is
    int j = 0;                 // the particle whose position or velocity it is
    Mat3 dfdx = Mat3::Zero();  // d f_i / d x_j
    Mat3 dfdv = Mat3::Zero();  // d f_i / d v_j
  };
  // Adds block (i, j); no allocation once the list has grown to its steady size.
  void add(int i, int j, const Mat3& dfdx, const Mat3& dfdv) {
    blocks_.push_back({i, j, dfdx, dfdv});
  }
  // Forgets the blocks, keeping the memory (no allocation in steady state).
  void clear() { blocks_.clear(); }
  // True when no block was added since the last clear().
  bool empty() const { return blocks_.empty(); }
  // The blocks in the order they were added.
  const std::vector<Block>& blocks() const { return blocks_; }
  // y += (df/dx) p and z += (df/dv) p (dense 3N vectors).
  void multiply(const VecX& p, VecX& dfdx_p, VecX& dfdv_p) const;
  // Throws InputError naming `force` when a block's index is outside [0, num_particles) or a
  // value is not finite.
  void validate(int num_particles, const std::string& force) const;

 private:
  std::vector<Block> blocks_;
};

// A force of the user's or of jelly's own, added at every force evaluation of every integrator; it
// may give its Jacobians for the implicit solvers.
class Force {
 public:
  virtual ~Force() = default;
  // A short name for messages and notes ("vortex", "spring_to_anchor").
  virtual std::string name() const = 0;
  // f += this force at time t on positions x and velocities v (all of size 3N). Called at every
  // force evaluation (each stage of a multi-stage method), from the thread that steps.
  virtual void add_forces(Real t, const VecX& x, const VecX& v, VecX& f) const = 0;
  // True when add_jacobian() gives the force's df/dx and df/dv. Without them an implicit
  // integrator treats the force explicitly within its step (the run report's notes say so).
  virtual bool has_jacobian() const { return false; }
  // Adds the blocks of df/dx and df/dv at (t, x, v). The implicit solve uses their symmetric
  // part (Cholesky and CG need a symmetric matrix); a force whose Jacobian is not symmetric
  // still gets its exact force, with a less exact linearization.
  virtual void add_jacobian(Real /*t*/, const VecX& /*x*/, const VecX& /*v*/,
                            ForceJacobian& /*jacobian*/) const {}
  // Throws InputError when the force cannot act on a model of `num_particles` particles (an
  // index out of range); called when the force is added and when the model changes.
  virtual void validate(int /*num_particles*/) const {}
};

// The forces added to a simulator, evaluated in this order after jelly's own.
using ForceList = std::vector<std::shared_ptr<Force>>;

// How far a force's Jacobians are from central differences of its forces at (t, x, v): the
// largest entry of |J - J_fd| over the largest entry of |J_fd| (or of |J|; 1 when both are 0),
// for df/dx and df/dv. Dense: meant for tests on small models.
struct JacobianCheck {
  Real dfdx_error = 0;  // relative error of df/dx
  Real dfdv_error = 0;  // relative error of df/dv
  Real dfdx_scale = 0;  // largest entry of |df/dx|, for stating an absolute tolerance
  Real dfdv_scale = 0;  // largest entry of |df/dv|
};
// The JacobianCheck of `force` at (t, x, v), with central differences of step `step`.
JacobianCheck check_force_jacobian(const Force& force, Real t, const VecX& x, const VecX& v,
                                   Real step = 1e-6);

}  // namespace jelly

// Springs from particles to points in space: pulls from outside the model (the viewer drags a
// particle with one). Each acts on one particle, so its Jacobian is diagonal and the implicit
// integrators add it to their matrix (core/detail/anchor_jacobian.hpp; an explicit treatment of
// a stiff pull at a large step would be unstable).
namespace jelly {

// A spring from particle `particle` to a point in space (the viewer's drag).
struct AnchorSpring {
  int particle = 0;      // the particle pulled
  Vec3 target{0, 0, 0};  // m
  Real stiffness = 0;    // k, N/m, >= 0
  Real damping = 0;      // c, N s/m, >= 0, on the particle's own velocity
};
using AnchorSprings = std::vector<AnchorSpring>;  // the anchor springs of a simulator

// Throws InputError for a particle index outside [0, num_particles), a non-finite target or a
// negative or non-finite coefficient.
void validate_anchors(const AnchorSprings& anchors, int num_particles);

// f_p += -k (x_p - target) - c v_p for every anchor. No allocation.
void add_anchor_forces(const AnchorSprings& anchors, const VecX& x, const VecX& v, VecX& f);

}  // namespace jelly

// How the geometric (transverse) stiffness of a spring is kept from making -K indefinite
// (docs/implicit.md): an option of the implicit integrators.
namespace jelly {

// Per spring, the symmetric part of -df_a/dxa is ks u u^T + s P, with P = I - u u^T,
// s = ks (1 - l0/L) + kd c / L (c = (va - vb).u); it is negative for a compressed (or a closing)
// spring.
enum class DefinitenessFix {
  kClampCompressed,  // Choi & Ko 2002: ks (1 - l0/L) and kd c/L each clamped to >= 0 (default)
  kProjectPsd,       // the spring's 3x3 block projected to PSD: s clamped to >= 0
  kNone,             // the exact symmetric Jacobian; M - h D - h^2 K may be indefinite
};
// "clamp", "project", "none".
const std::vector<EnumName<DefinitenessFix>>& definiteness_fixes();
// The name of `fix` in definiteness_fixes().
std::string_view definiteness_name(DefinitenessFix fix);

}  // namespace jelly
