#pragma once
// Options of the implicit Euler integrator (docs/implicit.md): each named choice an enum with its
// name table (core/enum_names.hpp), read from and written to a scene's integrator.options, and
// validated once with the JSON path of the field.
#include <string>
#include <vector>

#include <jelly/core/definiteness.hpp>
#include <jelly/core/enum_names.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>
#include <jelly/solvers/linear/cholmod_options.hpp>

namespace jelly {

enum class ImplicitLinearSolver {
  kAuto,     // CHOLMOD up to 1000 unknowns, block-Jacobi CG above (the fastest measured there)
  kCholmod,  // CHOLMOD, a numeric factorization every step
  kLdlt,     // Eigen's simplicial LDL^T, a factorization every step
  kCg,       // conjugate gradients with cg_preconditioner
};
const std::vector<EnumName<ImplicitLinearSolver>>& implicit_linear_solvers();

enum class CgPreconditionerKind {
  kJacobi,   // 3x3 block Jacobi
  kCholmod,  // a CHOLMOD factor of an earlier matrix, refreshed when it stops paying
  // A geometric multigrid V-cycle on lattice bodies (matrix-free CG; block Jacobi elsewhere)
  kMultigrid,
  // Smoothed-aggregation algebraic multigrid on any body (the assembled matrix's CG)
  kAmg,
};
const std::vector<EnumName<CgPreconditionerKind>>& cg_preconditioner_kinds();

// The cycle of cg_preconditioner = amg (docs/implicit.md, "Algebraic multigrid on any body").
enum class AmgCycle {
  kW,  // Chebyshev smoothing of degree 2 on level 0 and 4 below, levels below 1 visited twice
  kV,  // a V-cycle, Chebyshev smoothing of degree 2 on every level
};
const std::vector<EnumName<AmgCycle>>& amg_cycles();

// How coulomb terrains enter the step.
enum class ImplicitContactMode {
  kImplicit,   // constraints inside the linear solve, with friction and restitution
  kAfterStep,  // the resolve after the step of the explicit integrators (crushes at large dt)
};
const std::vector<EnumName<ImplicitContactMode>>& implicit_contact_modes();

struct ImplicitEulerOptions {
  // 1 = linearized backward Euler (Baraff & Witkin 1998), one linear solve per step;
  // > 1 = fully nonlinear backward Euler by Newton, at most this many linear solves per step.
  int newton_iterations = 1;
  // Newton stops when |M (v1 - v0) - h f(x0 + h v1, v1)| <= newton_tolerance |h f(x0, v0)|.
  Real newton_tolerance = 1e-8;
  DefinitenessFix definiteness = DefinitenessFix::kClampCompressed;
  ImplicitLinearSolver linear_solver = ImplicitLinearSolver::kAuto;
  // For kCg: the lagged CHOLMOD factor is refreshed when its solves cost more than the average
  // since the refresh, when CG needs more than refactor_iterations with it, or when dt changes.
  CgPreconditionerKind cg_preconditioner = CgPreconditionerKind::kJacobi;
  // 1e-5: at dt = 1/60 the solve then moves the particles about 1/1000 of backward Euler's own
  // error (docs/implicit.md, "CG tolerance").
  Real cg_tolerance = 1e-5;  // relative residual |b - A x| / |b|
  int cg_max_iterations = 1000;
  int refactor_iterations = 20;
  AmgCycle amg_cycle = AmgCycle::kW;                   // cg_preconditioner = amg: its cycle
  CholmodOrdering ordering = CholmodOrdering::kMetis;  // CHOLMOD's fill-reducing ordering
  ImplicitContactMode contact = ImplicitContactMode::kImplicit;
  // kImplicit: at most this many linear solves per step while the active set changes.
  int contact_iterations = 10;
  // kImplicit with the matrix-free CG: when > cg_tolerance, each solve of a step with contacts
  // first runs CG only to this relative residual, enough to see whether the contacts' set
  // changes; only a solve that keeps the set is finished to cg_tolerance (and its impulses and
  // friction taken from there). Fewer CG iterations when the set changes often; the jelly
  // ends about as far from an unscreened run as cg_tolerance's own error (docs/implicit.md,
  // "Screening the contacts' set"). 0 = off.
  Real contact_screening_tolerance = 1e-3;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix) const;
  // The scene's integrator.options of implicit_euler; validated with the fields' JSON path.
  static ImplicitEulerOptions read(JsonFields& fields);
  Json to_json() const;
};

}  // namespace jelly
