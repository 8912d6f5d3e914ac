#pragma once
// Projective dynamics (Liu et al. 2013, Bouaziz et al. 2014) for springs with dampers: the
// backward-Euler step solved by local/global iterations on one prefactored N x N matrix, shared
// by x, y and z,
//   A = M / h^2 + L_ks + L_kd / h       (L_w: the spring Laplacian weighted by w),
// factorized by CHOLMOD once per model and time step. Each iteration is
//   x <- x + A^-1 r(x),   r(x) = f(x, v) - M (v - v0) / h,   v = (x - x0) / h,
// which for springs alone is exactly Liu's local step (each spring's rest-length projection)
// followed by the global solve. The dampers' backward-Euler force is in r and their isotropic
// bound kd / h in A, so the fixed point is the nonlinear backward-Euler step with the dampers
// (what implicit_euler's Newton converges to). Optional Chebyshev acceleration (Wang 2015);
// coulomb terrains by projection inside the iterations (position_contact.hpp); docs/realtime.md.
#include <memory>
#include <vector>

#include <jelly/core/detail/sparse_matrix.hpp>
#include <jelly/core/force.hpp>
#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class PositionContact;

class CholmodSolver;

class ProjectiveDynamics final : public Integrator {
 public:
  // Throws InputError for invalid options.
  explicit ProjectiveDynamics(ProjectiveDynamicsOptions options = {});
  ~ProjectiveDynamics() override;

  std::string_view name() const override { return "projective_dynamics"; }
  int order() const override { return 1; }
  bool is_implicit() const override { return true; }
  // Every force, added ones included, is evaluated at each iterate (the fixed point is the
  // implicit step); an added force's Jacobian goes into the factor as the anchors' does.
  bool uses_force_jacobians() const override { return true; }
  std::string without_force_jacobian() const override {
    return "projective_dynamics evaluates it at every iterate, but its factor leaves it out "
           "(a stiff force can keep the iterations from converging)";
  }
  // steps, symbolic_analyses, factorizations (once per model and dt), iterations (global
  // solves), not_converged (steps that ended above the tolerance), chebyshev_rho,
  // factorization_seconds, solve_seconds, contact_restitution_limited.
  Statistics statistics() const override;
  // With a tolerance > 0: the steps that used all iterations and ended above it.
  std::vector<ToleranceMiss> tolerance_misses() const override;
  // The measured Chebyshev spectral radius (empty when none was measured).
  std::vector<Real> internal_state() const override;
  void restore_internal_state(const std::vector<Real>& data) override;

  const ProjectiveDynamicsOptions& options() const { return options_; }
  // |r| at each iterate of the last step (the first is the inertial prediction's).
  const std::vector<Real>& last_residuals() const { return residuals_; }
  // The spectral radius the acceleration uses (the option, or the measured one; 0 before).
  Real chebyshev_rho() const { return rho_; }
  // x = P^-1 b (N x 3) with the factor of the last step, P = A plus the penalties it held (the
  // pins'): the preconditioner of projective_dynamics' adjoint. Fails before the first step.
  LinearResult solve_with_factor(const Eigen::MatrixXd& b, Eigen::MatrixXd& x);

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  // With contact = "projection", unless the last step's Dynamics carried no terrains (then
  // finish_step() resolves them all after the step).
  bool contact_in_step() const {
    return options_.contact == PositionContactMode::kProjection && terrains_seen_;
  }
  // (Re)builds and factorizes A when the model or h changed.
  StepResult prepare(const Model& model, Real h);
  // r_ at the iterate x_ (v_ = (x_ - x0) / h), with the contact forces taken out.
  void residual(const Dynamics& dynamics, const State& s0, Real h);
  // When every contact slides, the uniform translation of the model along the surfaces
  // (which the contact penalties in the factor resist) is solved exactly and taken out of r_:
  // shift_ = h^2 (sum of r_ along the surfaces) / total mass, r_ -= M shift_ / h^2.
  void slide_correction(const Model& model, Real h);
  // delta_ = P^-1 r_, P = A + the contact penalties in the factor.
  StepResult solve();
  // Pinned particles at their paths' positions at time t (in x_).
  void place_pins(const Model& model, Real t);
  // pinned_ from the model's pins (each is held in the factor like a sticking contact, and its
  // residual is the pin's).
  void set_pins(const Pins& pins);
  // anchor_weight_ = k + c / h of the anchor springs, per particle, plus the stiffness of the
  // added forces' Jacobians at the step's start: each diagonal block's largest eigenvalue of
  // -(df/dx + df/dv / h), rounded up to a power of two (so that slowly changing Jacobians
  // seldom update the factor). The factor's diagonal then bounds the force's stiffness from
  // above (for forces between pairs of particles within a factor of two), which keeps the
  // iterations converging where a stiff force would make them diverge.
  void set_anchor_weights(const Dynamics& dynamics, const State& s, Real h);
  // Brings the diagonal additions in the factor in line with the anchors and the contacts'
  // modes (rank updates of the factor, no factorization).
  StepResult sync_penalties();

  ProjectiveDynamicsOptions options_;
  std::unique_ptr<CholmodSolver> solver_;
  SparseMatrix a_;
  Real h_ = 0;
  // What A was built from: a changed model rebuilds it.
  VecX mass_;
  std::vector<Real> ks_, kd_;
  std::vector<int> spring_a_, spring_b_;
  Eigen::MatrixXd rhs_, solution_;  // N x 3
  VecX x_, x_prev_, v_, f_, r_, delta_;
  VecX diagonal_;                    // A's diagonal
  Vec3 shift_ = Vec3::Zero();        // slide_correction's translation
  std::vector<Real> penalty_;        // [N]: what the factor holds beyond A (anchors, contacts)
  std::vector<Real> anchor_weight_;  // [N]: k + c / h of the anchor springs
  std::vector<int> anchored_;
  ForceJacobian jacobian_;    // the added forces' blocks at the step's start
  std::vector<char> pinned_;  // [N]
  std::vector<int> pinned_list_;
  std::vector<int> penalized_list_, rows_;
  std::vector<Real> values_;
  std::unique_ptr<PositionContact> contact_;  // detail/position_contact.hpp
  bool contact_active_ = false;
  bool terrains_seen_ = true;
  Real rho_ = 0;  // Chebyshev spectral radius in use
  std::vector<Real> residuals_, step_norms_;
  long analyses_ = 0, factorizations_ = 0, iterations_ = 0, not_converged_ = 0;
  long rank_updates_ = 0;
  double factorization_seconds_ = 0, solve_seconds_ = 0;
};

}  // namespace jelly
