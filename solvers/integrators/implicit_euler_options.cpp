#include <jelly/solvers/integrators/integrator_options.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>

namespace jelly {

const std::vector<EnumName<ImplicitLinearSolver>>& implicit_linear_solvers() {
  static const std::vector<EnumName<ImplicitLinearSolver>> table{
      {ImplicitLinearSolver::kAuto, "auto", "cholmod up to 1000 unknowns, cg (block Jacobi) above"},
      {ImplicitLinearSolver::kCholmod, "cholmod", "CHOLMOD sparse Cholesky every step"},
      {ImplicitLinearSolver::kLdlt, "ldlt", "Eigen simplicial LDL^T every step"},
      {ImplicitLinearSolver::kCg, "cg", "conjugate gradients with cg_preconditioner"},
  };
  return table;
}

const std::vector<EnumName<CgPreconditionerKind>>& cg_preconditioner_kinds() {
  static const std::vector<EnumName<CgPreconditionerKind>> table{
      {CgPreconditionerKind::kJacobi, "jacobi", "3x3 block Jacobi"},
      {CgPreconditionerKind::kCholmod, "cholmod", "a lagged CHOLMOD factor of an earlier matrix"},
      {CgPreconditionerKind::kMultigrid, "multigrid",
       "a geometric multigrid V-cycle on lattice bodies (block Jacobi on the others)"},
      {CgPreconditionerKind::kAmg, "amg",
       "a smoothed-aggregation algebraic multigrid cycle on any body (assembled matrix)"},
  };
  return table;
}

const std::vector<EnumName<AmgCycle>>& amg_cycles() {
  static const std::vector<EnumName<AmgCycle>> table{
      {AmgCycle::kW, "w",
       "Chebyshev smoothing of degree 2 on level 0 and 4 below, a W-cycle below level 1"},
      {AmgCycle::kV, "v", "a V-cycle, Chebyshev smoothing of degree 2 on every level"},
  };
  return table;
}

const std::vector<EnumName<ImplicitContactMode>>& implicit_contact_modes() {
  static const std::vector<EnumName<ImplicitContactMode>> table{
      {ImplicitContactMode::kImplicit, "implicit",
       "coulomb contact as constraints inside the solve"},
      {ImplicitContactMode::kAfterStep, "after_step",
       "the explicit integrators' resolve after the step"},
  };
  return table;
}

const FieldTable<ImplicitEulerOptions>& implicit_euler_fields() {
  using O = ImplicitEulerOptions;
  static const FieldTable<O> table{
      "ImplicitEulerOptions",
      "integrator.options",
      "Options of implicit_euler (docs/implicit.md)",
      {
          integer_field<&O::newton_iterations>(
              "newton_iterations", "", range_closed(1, 100),
              "an integer in [1, 100] (1 = linearized backward Euler)",
              "1 = linearized backward Euler; > 1 = Newton, at most this many solves per step"),
          number_field<&O::newton_tolerance>("newton_tolerance", "", range_open(0, 1),
                                             "a relative tolerance in (0, 1)",
                                             "Newton's relative tolerance on the residual"),
          choice_field<&O::definiteness, &definiteness_fixes>(
              "definiteness", "How compressed springs keep the matrix positive definite"),
          choice_field<&O::linear_solver, &implicit_linear_solvers>(
              "linear_solver", "The linear solver of each Newton step"),
          choice_field<&O::cg_preconditioner, &cg_preconditioner_kinds>(
              "cg_preconditioner",
              "CG's preconditioner (multigrid: lattice bodies; amg: any body, where CG solves: "
              "linear_solver cg, or auto above 1000 unknowns)"),
          number_field<&O::cg_tolerance>("cg_tolerance", "", range_open(0, 1),
                                         "a relative residual in (0, 1)",
                                         "CG's relative residual |b - A x| / |b|"),
          integer_field<&O::cg_max_iterations>("cg_max_iterations", "", range_at_least(1),
                                               "an integer >= 1", "CG iterations at most"),
          integer_field<&O::refactor_iterations>(
              "refactor_iterations", "", range_at_least(1), "an integer >= 1",
              "CG iterations that trigger a new CHOLMOD preconditioner (amg: a refresh of its "
              "coarse levels; 1 = every step)"),
          choice_field<&O::amg_cycle, &amg_cycles>("amg_cycle",
                                                   "The cycle of cg_preconditioner amg"),
          choice_field<&O::ordering, &cholmod_orderings>("ordering",
                                                         "CHOLMOD's fill-reducing ordering"),
          choice_field<&O::contact, &implicit_contact_modes>("contact",
                                                             "How coulomb terrains enter the step"),
          integer_field<&O::contact_iterations>(
              "contact_iterations", "", range_closed(1, 100), "an integer in [1, 100]",
              "Linear solves per step at most while the set of contacts changes"),
          number_field<&O::contact_screening_tolerance>(
              "contact_screening_tolerance", "", range_or_zero(range_open(0, 1)),
              "0 (off) or a relative residual in (0, 1)",
              "A looser CG residual at which each solve of a step with contacts first checks "
              "the contacts' set; 0 = off"),
      },
  };
  return table;
}

void ImplicitEulerOptions::validate(const std::string& prefix) const {
  validate_fields(implicit_euler_fields(), *this, prefix);
}

ImplicitEulerOptions ImplicitEulerOptions::read(JsonFields& f) {
  ImplicitEulerOptions o;
  read_fields(implicit_euler_fields(), f, o, f.prefix());
  return o;
}

Json ImplicitEulerOptions::to_json() const {
  Json out = Json::object();
  write_fields(implicit_euler_fields(), *this, out);
  return out;
}

}  // namespace jelly
