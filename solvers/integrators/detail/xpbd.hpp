#pragma once
// Extended position-based dynamics (Macklin et al. 2016) with small steps (Macklin et al. 2019):
// each step of h is split into `substeps` substeps of hs = h / substeps; per substep the
// particles move under gravity (and the seed model's contact forces), then `iterations`
// Jacobi sweeps project every spring C = |xa - xb| - l0 with compliance alpha = 1 / ks and
// damping kd from the same positions:
//   dlambda = (-ks hs^2 C - lambda - kd hs grad C . (x - x_start)) / ((ks hs^2 + kd hs) w' + 1),
//   xa += wa dlambda n, xb -= wb dlambda n      (n = grad_a C, summed over a particle's springs),
// which is Macklin 2016's update (alpha~ = alpha / hs^2, gamma = alpha~ beta~ / hs, beta = kd)
// multiplied through by ks hs^2, so that ks = 0 (a pure damper) is allowed. The springs share
// each particle's mass (mass splitting): w' = sa wa + sb wb, sa the largest eigenvalue of
// sum n n^T over the springs at a at rest (at most their number), which bounds the summed
// corrections (J W J^T <= diag(w'): no relaxation factor to tune) and keeps every correction
// an equal and opposite impulse along the spring: the sweeps conserve linear and
// angular momentum, give mirror-symmetric results for mirror-symmetric inputs (no order among
// the springs) and the same bits for any thread count; a fixed point is the XPBD solution.
// (XpbdOptions::sweep = gauss_seidel: the original sweep, one spring after the other with
// w' = wa + wb, faster to carry a correction through a lattice, not symmetric.)
// Anchor springs are constraints of the same kind to their target (per particle, after the
// springs). Coulomb terrains are position constraints with position-based friction in each
// sweep, and restitution after each substep (position_contact.hpp); docs/realtime.md.
#include <memory>
#include <vector>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

class PositionContact;

class Xpbd final : public Integrator {
 public:
  // Throws InputError for invalid options.
  explicit Xpbd(XpbdOptions options = {});
  ~Xpbd() override;

  std::string_view name() const override { return "xpbd"; }
  int order() const override { return 1; }
  // The springs are solved implicitly (compliant constraints): stable at any step.
  bool is_implicit() const override { return true; }
  // steps, substeps, sweeps, contact_restitution_limited.
  Statistics statistics() const override;

  const XpbdOptions& options() const { return options_; }

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  // With contact = "projection", unless the last step's Dynamics carried no terrains (then
  // finish_step() resolves them all after the step).
  bool contact_in_step() const {
    return options_.contact == PositionContactMode::kProjection && terrains_seen_;
  }
  // One spring as the sweep reads it: coefficients premultiplied for the substep size.
  struct Constraint {
    int a, b;
    Real rest;
    Real stiffness;            // ks hs^2
    Real damping;              // kd hs
    Real inverse_denominator;  // 1 / ((ks hs^2 + kd hs) (na wa + nb wb) + 1)
  };
  void prepare(const Model& model, Real hs);
  // One Jacobi sweep over the springs on up to `threads` threads.
  void sweep(VecX& x, int threads);
  // One Gauss-Seidel sweep over the springs in the model's order (XpbdSweep::kGaussSeidel).
  void sweep_in_order(VecX& x);
  void sweep_anchors(const AnchorSprings& anchors, Real hs, VecX& x);
  // Pinned particles (inverse mass 0 in the sweeps) at their paths' positions at time t.
  void place_pins(const Pins& pins, Real t, VecX& x) const;

  XpbdOptions options_;
  std::vector<Constraint> constraints_;
  VecX inverse_mass_;
  Real hs_ = 0;
  // What the constraints were built from: a changed model rebuilds them.
  VecX mass_;
  std::vector<Real> ks_, kd_, rest_;
  std::vector<int> spring_a_, spring_b_, pinned_;
  VecX rest_position_;
  VecX x_start_, lambda_, f_;
  // The springs at each particle (CSR over particles): k for the spring's end a, ~k for its
  // end b; and each spring's impulse dlambda n of the current sweep, [3 x springs].
  std::vector<int> incidence_start_, incidence_;
  std::vector<Real> impulse_;
  VecX split_;  // per particle: the share its springs split its mass into (Jacobi)
  std::vector<Vec3> anchor_lambda_;
  std::unique_ptr<PositionContact> contact_;  // detail/position_contact.hpp
  bool contact_active_ = false;
  bool terrains_seen_ = true;
  long substeps_ = 0, sweeps_ = 0;
};

}  // namespace jelly
