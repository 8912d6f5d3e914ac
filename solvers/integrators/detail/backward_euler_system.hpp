#pragma once
// The linear system of a backward-Euler step and its solve, as ImplicitEuler drives it:
//   A = M - h D - h^2 K (+ anchors, added forces' Jacobians, wind drag),  A y = b,
// filtered by the contact constraints of the step (ImplicitContact) when it has any. Two
// implementations: AssembledSystem (a sparse matrix for CHOLMOD, LDLT or CG) and
// MatrixFreeSystem (the springs' bands, block-Jacobi or multigrid CG, no matrix). Every call is
// per assembly or per solve, never per spring.
#include <string_view>

#include <jelly/core/types.hpp>
#include <jelly/solvers/dynamics.hpp>
#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class ImplicitContact;

// The time a system spends, added into ImplicitEuler's statistics.
struct SystemTimes {
  double assembly = 0, factorization = 0, solve = 0;
};

class BackwardEulerSystem {
 public:
  virtual ~BackwardEulerSystem() = default;

  // The backend, as ImplicitEuler::linear_solver_name() reports it.
  virtual std::string_view name() const = 0;
  virtual int rows() const = 0;
  // The threads of the coming step's products and solves.
  virtual void set_threads(int threads) = 0;
  // dt changed: what was computed for the old one (factorizations, coarse operators) is stale.
  virtual void invalidate() = 0;

  // The added forces' Jacobian blocks at (t, x, v), for the next assemble(). Throws InputError
  // for a block out of range or not finite, naming the force.
  virtual StepResult collect_force_jacobians(const Dynamics& dynamics, const VecX& x, const VecX& v,
                                             Real t) = 0;
  // Whether the last collect_force_jacobians() found blocks.
  virtual bool has_force_terms() const = 0;
  // A at (x, v) for a step of size h, with kw = K v (the springs' and anchors' stiffness times
  // v). False when the system cannot represent it (the matrix-free system meets a collapsed
  // spring): the caller moves to an assembled system.
  virtual bool assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real h,
                        VecX& kw) = 0;
  // A(i, i) += value for each of particle i's three rows.
  virtual void add_diagonal(int particle, Real value) = 0;

  // The contact filter of the system and of its right-hand side b into rhs and z
  // (ImplicitContact::constrain; `prescribe` false for a Newton correction).
  virtual void constrain(ImplicitContact& contacts, const VecX& b, bool prescribe, VecX& rhs,
                         VecX& z, VecX& guess) = 0;
  // The contacts' next active set after a solve for dv (ImplicitContact::update); true when it
  // changed.
  virtual bool update_contacts(ImplicitContact& contacts, const Terrains& terrains, const VecX& b,
                               const VecX& dv, bool commit, bool screening) = 0;
  // Solves A y = b from the guess in y; `constraints`: A is filtered by them (null: not). An
  // iterative solve stops at the relative residual `tolerance`; `resume` continues the last
  // loose solve (matrix-free only).
  virtual LinearResult solve(const VecX& b, VecX& y, ImplicitContact* constraints, Real tolerance,
                             bool resume) = 0;

 protected:
  BackwardEulerSystem() = default;
  BackwardEulerSystem(const BackwardEulerSystem&) = default;
  BackwardEulerSystem& operator=(const BackwardEulerSystem&) = default;
};

}  // namespace jelly
