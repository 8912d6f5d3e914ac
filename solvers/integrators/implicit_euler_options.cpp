#include <jelly/solvers/integrators/implicit_euler_options.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

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
       "a smoothed-aggregation algebraic multigrid V-cycle on any body (assembled matrix)"},
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

void ImplicitEulerOptions::validate(const std::string& prefix) const {
  require(newton_iterations >= 1 && newton_iterations <= 100, prefix + "newton_iterations",
          newton_iterations, "an integer in [1, 100] (1 = linearized backward Euler)");
  require(std::isfinite(newton_tolerance) && newton_tolerance > 0 && newton_tolerance < 1,
          prefix + "newton_tolerance", newton_tolerance, "a relative tolerance in (0, 1)");
  require(std::isfinite(cg_tolerance) && cg_tolerance > 0 && cg_tolerance < 1,
          prefix + "cg_tolerance", cg_tolerance, "a relative residual in (0, 1)");
  require(cg_max_iterations >= 1, prefix + "cg_max_iterations", cg_max_iterations,
          "an integer >= 1");
  require(refactor_iterations >= 1, prefix + "refactor_iterations", refactor_iterations,
          "an integer >= 1");
  require(contact_iterations >= 1 && contact_iterations <= 100, prefix + "contact_iterations",
          contact_iterations, "an integer in [1, 100]");
  require(std::isfinite(contact_screening_tolerance) &&
              (contact_screening_tolerance == 0 ||
               (contact_screening_tolerance > 0 && contact_screening_tolerance < 1)),
          prefix + "contact_screening_tolerance", contact_screening_tolerance,
          "0 (off) or a relative residual in (0, 1)");
}

ImplicitEulerOptions ImplicitEulerOptions::read(JsonFields& f) {
  ImplicitEulerOptions o;
  const auto choice = [&f](const auto& table, const char* key, auto value) {
    const std::string name = f.string_or(key, std::string(name_of(table, value)));
    return value_of(table, name, f.path(key));
  };
  o.newton_iterations = f.integer_or("newton_iterations", o.newton_iterations);
  o.newton_tolerance = f.number_or("newton_tolerance", o.newton_tolerance);
  o.definiteness = choice(definiteness_fixes(), "definiteness", o.definiteness);
  o.linear_solver = choice(implicit_linear_solvers(), "linear_solver", o.linear_solver);
  o.cg_preconditioner = choice(cg_preconditioner_kinds(), "cg_preconditioner", o.cg_preconditioner);
  o.cg_tolerance = f.number_or("cg_tolerance", o.cg_tolerance);
  o.cg_max_iterations = f.integer_or("cg_max_iterations", o.cg_max_iterations);
  o.refactor_iterations = f.integer_or("refactor_iterations", o.refactor_iterations);
  o.ordering = choice(cholmod_orderings(), "ordering", o.ordering);
  o.contact = choice(implicit_contact_modes(), "contact", o.contact);
  o.contact_iterations = f.integer_or("contact_iterations", o.contact_iterations);
  o.contact_screening_tolerance =
      f.number_or("contact_screening_tolerance", o.contact_screening_tolerance);
  o.validate(f.prefix());
  return o;
}

Json ImplicitEulerOptions::to_json() const {
  Json out = Json::object();
  out["newton_iterations"] = newton_iterations;
  out["newton_tolerance"] = newton_tolerance;
  out["definiteness"] = std::string(name_of(definiteness_fixes(), definiteness));
  out["linear_solver"] = std::string(name_of(implicit_linear_solvers(), linear_solver));
  out["cg_preconditioner"] = std::string(name_of(cg_preconditioner_kinds(), cg_preconditioner));
  out["cg_tolerance"] = cg_tolerance;
  out["cg_max_iterations"] = cg_max_iterations;
  out["refactor_iterations"] = refactor_iterations;
  out["ordering"] = std::string(name_of(cholmod_orderings(), ordering));
  out["contact"] = std::string(name_of(implicit_contact_modes(), contact));
  out["contact_iterations"] = contact_iterations;
  out["contact_screening_tolerance"] = contact_screening_tolerance;
  return out;
}

}  // namespace jelly
