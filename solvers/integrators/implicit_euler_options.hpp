#pragma once
// Options of the implicit Euler integrator (docs/implicit.md), with a validity check that names
// the offending field.
#include <string>

#include <jelly/core/definiteness.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct ImplicitEulerOptions {
  // 1 = linearized backward Euler (Baraff & Witkin 1998), one linear solve per step;
  // > 1 = fully nonlinear backward Euler by Newton, at most this many linear solves per step.
  int newton_iterations = 1;
  // Newton stops when |M (v1 - v0) - h f(x0 + h v1, v1)| <= newton_tolerance |h f(x0, v0)|.
  Real newton_tolerance = 1e-8;
  DefinitenessFix definiteness = DefinitenessFix::kClampCompressed;
  // "cholmod" (factor every step), "ldlt" (Eigen, factor every step), "cg", or "auto":
  // CHOLMOD for up to 1000 unknowns, block-Jacobi CG above (the fastest measured there).
  std::string linear_solver = "auto";
  // For "cg": "jacobi" (3x3 block Jacobi) or "cholmod" (a CHOLMOD factor of an earlier matrix,
  // refreshed when its solves cost more than the average since the refresh, when CG needs more
  // than refactor_iterations with it, or when dt changes).
  std::string cg_preconditioner = "jacobi";
  Real cg_tolerance = 1e-8;  // relative residual |b - A x| / |b|
  int cg_max_iterations = 1000;
  int refactor_iterations = 20;
  // Fill-reducing ordering of CHOLMOD: "metis", "amd", "nesdis" or "best" (CHOLMOD's default).
  std::string ordering = "metis";
  // How coulomb terrains enter the step: "implicit" (constraints inside the linear solve, with
  // friction and restitution; solvers/contact/detail/implicit_contact.hpp) or "after_step" (the
  // resolve after the step that the explicit integrators use; it crushes the springs at large
  // steps).
  std::string contact = "implicit";
  // "implicit": at most this many linear solves per step while the active set changes.
  int contact_iterations = 10;

  // False, with "options.<field> = <value> is invalid: <allowed>" in *why, for the first
  // invalid field.
  bool is_valid(std::string* why) const;
};

}  // namespace jelly
