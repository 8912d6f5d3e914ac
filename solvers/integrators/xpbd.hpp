#pragma once
// Extended position-based dynamics (Macklin et al. 2016) with small steps (Macklin et al. 2019):
// each step of h is split into `substeps` substeps of hs = h / substeps; per substep the
// particles move under gravity (and the seed model's contact forces), then `iterations`
// Gauss-Seidel sweeps project each spring C = |xa - xb| - l0 with compliance alpha = 1 / ks and
// damping kd:
//   dlambda = (-ks hs^2 C - lambda - kd hs grad C . (x - x_start)) / ((ks hs^2 + kd hs) w + 1),
//   xa += wa dlambda n, xb -= wb dlambda n       (w = wa + wb inverse masses, n = grad_a C),
// which is Macklin 2016's update (alpha~ = alpha / hs^2, gamma = alpha~ beta~ / hs, beta = kd)
// multiplied through by ks hs^2, so that ks = 0 (a pure damper) is allowed; anchor springs are
// constraints of the same kind to their target. Coulomb terrains are
// position constraints with position-based friction in each sweep, and restitution after each
// substep (position_contact.hpp); docs/realtime.md.
#include <memory>
#include <vector>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/xpbd_options.hpp>

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
  bool resolves_contact() const override {
    return options_.contact == PositionContactMode::kProjection && terrains_seen_;
  }
  int contacts_resolved() const override;
  // steps, substeps, sweeps, contact_restitution_limited.
  Statistics statistics() const override;

  const XpbdOptions& options() const { return options_; }

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  // One spring as the sweep reads it: coefficients premultiplied for the substep size.
  struct Constraint {
    int a, b;
    Real rest;
    Real stiffness;            // ks hs^2
    Real damping;              // kd hs
    Real inverse_denominator;  // 1 / ((ks hs^2 + kd hs) (wa + wb) + 1)
  };
  void prepare(const Model& model, Real hs);
  void sweep(VecX& x);
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
  std::vector<Vec3> anchor_lambda_;
  std::unique_ptr<PositionContact> contact_;  // detail/position_contact.hpp
  bool contact_active_ = false;
  bool terrains_seen_ = true;
  long substeps_ = 0, sweeps_ = 0;
};

}  // namespace jelly
