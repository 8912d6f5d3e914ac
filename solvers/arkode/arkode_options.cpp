#include <jelly/solvers/arkode/arkode_options.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

void ArkodeOptions::validate() const {
  require(std::isfinite(rtol) && rtol > 0 && rtol < 1, "integrator.options.rtol", rtol,
          "a relative tolerance in (0, 1)");
  require(std::isfinite(atol) && atol > 0, "integrator.options.atol", atol,
          "an absolute tolerance > 0");
  require(std::isfinite(max_step) && max_step >= 0, "integrator.options.max_step", max_step,
          "a finite step >= 0 s (0 = the contact interval dt)");
  require(linear_solver == "schur" || linear_solver == "klu", "integrator.options.linear_solver",
          "\"" + linear_solver + "\"", "\"schur\" or \"klu\"");
  require(max_steps > 0, "integrator.options.max_steps", max_steps,
          "a number of internal steps per contact interval > 0");
}

}  // namespace jelly
