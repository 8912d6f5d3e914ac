#include <jelly/solvers/integrators/implicit_euler_options.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

namespace {

bool one_of(const std::string& value, std::initializer_list<const char*> allowed) {
  for (const char* a : allowed)
    if (value == a) return true;
  return false;
}

template <typename T>
bool fail(std::string* why, const char* field, const T& value, const char* allowed) {
  if (why) *why = InputError(std::string("options.") + field, to_text(value), allowed).what();
  return false;
}
// Text values are shown quoted, as in the scene file.
bool fail(std::string* why, const char* field, const std::string& value, const char* allowed) {
  return fail<std::string>(why, field, "\"" + value + "\"", allowed);
}

}  // namespace

bool ImplicitEulerOptions::is_valid(std::string* why) const {
  if (newton_iterations < 1 || newton_iterations > 100)
    return fail(why, "newton_iterations", newton_iterations,
                "an integer in [1, 100] (1 = linearized backward Euler)");
  if (!(std::isfinite(newton_tolerance) && newton_tolerance > 0 && newton_tolerance < 1))
    return fail(why, "newton_tolerance", newton_tolerance, "a relative tolerance in (0, 1)");
  if (definiteness != DefinitenessFix::kClampCompressed &&
      definiteness != DefinitenessFix::kProjectPsd && definiteness != DefinitenessFix::kNone)
    return fail(why, "definiteness", static_cast<int>(definiteness), "clamp, project or none");
  if (!one_of(linear_solver, {"auto", "cholmod", "ldlt", "cg"}))
    return fail(why, "linear_solver", linear_solver, "\"auto\", \"cholmod\", \"ldlt\" or \"cg\"");
  if (!one_of(cg_preconditioner, {"jacobi", "cholmod"}))
    return fail(why, "cg_preconditioner", cg_preconditioner, "\"jacobi\" or \"cholmod\"");
  if (!(std::isfinite(cg_tolerance) && cg_tolerance > 0 && cg_tolerance < 1))
    return fail(why, "cg_tolerance", cg_tolerance, "a relative residual in (0, 1)");
  if (cg_max_iterations < 1)
    return fail(why, "cg_max_iterations", cg_max_iterations, "an integer >= 1");
  if (refactor_iterations < 1)
    return fail(why, "refactor_iterations", refactor_iterations, "an integer >= 1");
  if (!one_of(ordering, {"metis", "amd", "nesdis", "best"}))
    return fail(why, "ordering", ordering, "\"metis\", \"amd\", \"nesdis\" or \"best\"");
  if (!one_of(contact, {"implicit", "after_step"}))
    return fail(why, "contact", contact, "\"implicit\" or \"after_step\"");
  if (contact_iterations < 1 || contact_iterations > 100)
    return fail(why, "contact_iterations", contact_iterations, "an integer in [1, 100]");
  return true;
}

}  // namespace jelly
