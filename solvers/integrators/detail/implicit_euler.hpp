#pragma once
// Backward (implicit) Euler on a sparse linear solver: per step
//   (M - h D - h^2 K) dv = h (f + h K v),  v += dv,  x += h v      (Baraff & Witkin 1998)
// with K = df/dx and D = df/dv of the springs and dampers, or, with newton_iterations > 1,
// Newton's method on the nonlinear backward-Euler equations. Order 1, stable at any dt. With
// the option contact = "implicit" (default) the coulomb terrains' contact and friction are
// constraints of the same solve (docs/implicit.md, "Contact inside the solve").
#include <memory>
#include <string>
#include <vector>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

class ImplicitEuler final : public Integrator {
 public:
  // Throws InputError for invalid options.
  explicit ImplicitEuler(ImplicitEulerOptions options = {});
  ~ImplicitEuler() override;

  std::string_view name() const override { return "implicit_euler"; }
  int order() const override { return 1; }
  bool is_implicit() const override { return true; }
  bool uses_force_jacobians() const override { return true; }
  // steps, symbolic_analyses, numeric_factorizations, linear_solves, cg_iterations,
  // newton_iterations, newton_not_converged, assembly_seconds, factorization_seconds,
  // solve_seconds, and for contact inside the solve contact_extra_solves,
  // contact_not_converged, contact_restitution_limited, and with contact between bodies inside
  // the solve body_contact_extra_solves, body_contact_not_converged, body_contact_projected,
  // body_contact_restitution_limited.
  Statistics statistics() const override;
  // With newton_iterations > 1: the steps whose Newton iterations stopped at the limit above
  // newton_tolerance.
  std::vector<ToleranceMiss> tolerance_misses() const override;
  // The CG warm start, the active contact pairs between bodies (with their friction state) and
  // the terrain contact set (a lagged CHOLMOD preconditioner is not kept: it is rebuilt, so only
  // the backends without one restart bit for bit).
  std::vector<Real> internal_state() const override;
  void restore_internal_state(const std::vector<Real>& data) override;

  const ImplicitEulerOptions& options() const;
  // The backend chosen ("cholmod", "ldlt", "cg_jacobi", "cg_lagged_cholmod"); empty before the
  // first step.
  std::string_view linear_solver_name() const;
  // Newton: the residual norms |M (v1 - v0) - h f(x0 + h v1, v1)| of the last step, one per
  // iterate after the first (linearized) solve, and whether the last step converged.
  const std::vector<Real>& last_residuals() const;
  bool last_converged() const;

  // A velocity constraint of the last step's final linear solve (docs/gradients.md), as the
  // discrete adjoint (solvers/adjoint/) holds it fixed: a pin (v1 prescribed), a sticking contact
  // (v1 prescribed: the surface's tangential velocity, the normal velocity that lands it) or a
  // sliding one (normal velocity prescribed, friction viscosity on the tangent plane).
  struct SolvedConstraint {
    enum class Kind { kPin, kStick, kSlide };
    int particle = 0;
    Kind kind = Kind::kPin;
    Vec3 normal = Vec3::UnitY();
    Vec3 surface_velocity = Vec3::Zero();
    Real viscosity = 0;    // sliding only
    bool bounces = false;  // restitution changes its velocity at the end of the step
    Real friction = 0, static_friction = 0;  // the terrain's mu and mu_s
    // The constraint impulse p = (A dv - b) of the particle after the solve (the next step's
    // friction viscosity comes from it).
    Vec3 impulse = Vec3::Zero();
  };
  // The constraints of the last step's final solve (empty when it had none); with
  // newton_iterations > 1, of its Newton iterates (the friction as the last solve updated it;
  // impulse zero).
  const std::vector<SolvedConstraint>& last_constraints() const;
  // The last step's velocity change dv (v1 = v0 + dv before the contacts' end of step and the
  // pins); with newton_iterations > 1, v1 - v0 of the last Newton iterate.
  const VecX& last_velocity_change() const;
  // Whether the last step's solve held contact pairs between bodies.
  bool last_step_had_body_contact() const;
  // An active contact pair between bodies of the last step's final linear solve
  // (docs/gradients.md), as the adjoint holds it fixed: the impulse on j (on i the opposite) is
  //   -(kappa mass / h) (gap0 + h normal.w1) normal - c P_t w1,  w1 = v1_j - v1_i,
  // with c = kappa mass while it sticks, `viscosity` while it slides
  // (solvers/contact/detail/implicit_body_contact.hpp).
  struct SolvedPair {
    int i = 0, j = 0;
    Vec3 normal = Vec3::UnitY();  // from x_i0 to x_j0
    Real gap0 = 0;                // |x_j0 - x_i0| - (r_i + r_j)
    Real mass = 0;                // reduced mass (a pinned partner is infinitely heavy)
    Real approach = 0;            // -(w0 . normal) at the start of the step
    Real kappa = 0;
    bool slide = false;
    Real viscosity = 0;  // sliding only
  };
  // The active pairs of the last step's final solve (empty when it had none).
  const std::vector<SolvedPair>& last_pairs() const;

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  struct Impl;  // the Jacobian, the linear solver, the contact set and the work vectors
  std::unique_ptr<Impl> impl_;
};

// The backend "auto" picks for a system of `dofs` unknowns (docs/implicit.md).
ImplicitLinearSolver auto_linear_solver(int dofs);

}  // namespace jelly
