#pragma once
// Backward (implicit) Euler on a sparse linear solver: per step
//   (M - h D - h^2 K) dv = h (f + h K v),  v += dv,  x += h v      (Baraff & Witkin 1998)
// with K = df/dx and D = df/dv of the springs and dampers, or, with newton_iterations > 1,
// Newton's method on the nonlinear backward-Euler equations. Order 1, stable at any dt. With
// the option contact = "implicit" (default) the coulomb terrains' contact and friction are
// constraints of the same solve (implicit_contact.hpp).
#include <memory>
#include <optional>
#include <vector>

#include <jelly/core/jacobian.hpp>
#include <jelly/solvers/contact/implicit_contact.hpp>
#include <jelly/solvers/integrators/implicit_euler_options.hpp>
#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/linear/linear_solver.hpp>

namespace jelly {

class ImplicitEuler final : public Integrator {
 public:
  // Throws InputError for invalid options.
  explicit ImplicitEuler(ImplicitEulerOptions options = {});

  std::string_view name() const override { return "implicit_euler"; }
  int order() const override { return 1; }
  bool is_implicit() const override { return true; }
  // With contact = "implicit", unless the last step's Dynamics carried no terrains (then the
  // caller's resolve after the step must handle them all).
  bool resolves_contact() const override {
    return options_.contact == "implicit" && terrains_seen_;
  }
  int contacts_resolved() const override { return contact_active_ ? contact_.count() : 0; }
  // steps, symbolic_analyses, numeric_factorizations, linear_solves, cg_iterations,
  // newton_iterations, newton_not_converged, assembly_seconds, factorization_seconds,
  // solve_seconds, and for contact inside the solve contact_extra_solves,
  // contact_not_converged, contact_restitution_limited.
  Statistics statistics() const override;
  // The CG warm start and the contact set (a lagged CHOLMOD preconditioner is not kept: it is
  // rebuilt, so only the backends without one restart bit for bit).
  std::vector<Real> internal_state() const override;
  void restore_internal_state(const std::vector<Real>& data) override;

  const ImplicitEulerOptions& options() const { return options_; }
  // The backend chosen ("cholmod", "ldlt", "cg_jacobi", "cg_lagged_cholmod"); empty before the
  // first step.
  std::string_view linear_solver_name() const;
  // Newton: the residual norms |M (v1 - v0) - h f(x0 + h v1, v1)| of the last step, one per
  // iterate after the first (linearized) solve, and whether the last step converged.
  const std::vector<Real>& last_residuals() const { return residuals_; }
  bool last_converged() const { return converged_; }

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  StepResult prepare(const Model& model, Real h);
  // Factorizes A (filtered by the contact constraints, if any) and solves for dv_: the
  // linearized step, repeated while the contacts' active set changes.
  StepResult linearized_solve(const Dynamics& dynamics, const State& s, Real h);
  // Factorizes a_ and solves a_ y = b (constrained: a_ is filtered by contacts).
  StepResult factorize_and_solve(const Model& model, const VecX& b, VecX& y, bool constrained,
                                 Real t);
  // Newton corrections on the nonlinear backward-Euler equations from v1_.
  StepResult newton(const Dynamics& dynamics, const State& s, Real h);

  ImplicitEulerOptions options_;
  JacobianOptions jacobian_options_;
  std::optional<SpringJacobian> jacobian_;
  std::unique_ptr<LinearSolver> solver_;
  SparseMatrix a_;
  VecX f_, kw_, b_, dv_, v1_, x1_, g_, delta_, rhs_, z_;
  ImplicitContact contact_;
  bool contact_active_ = false;  // the current step constrains contacts
  bool terrains_seen_ = true;    // the last step's Dynamics had terrains
  bool anchored_ = false;        // the current step's Dynamics has anchor springs
  Real last_h_ = 0;
  bool have_dv_ = false;
  std::vector<Real> residuals_;
  bool converged_ = true;
  long newton_iterations_ = 0;
  long newton_not_converged_ = 0;
  double assembly_seconds_ = 0, factorization_seconds_ = 0, solve_seconds_ = 0;
};

// The backend "auto" picks for a system of `dofs` unknowns (docs/implicit.md).
std::string auto_linear_solver(int dofs);

}  // namespace jelly
