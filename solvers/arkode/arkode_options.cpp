#include <jelly/solvers/arkode/arkode_options.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

void ArkodeOptions::validate(const std::string& prefix) const {
  require(std::isfinite(rtol) && rtol > 0 && rtol < 1, prefix + "rtol", rtol,
          "a relative tolerance in (0, 1)");
  require(std::isfinite(atol) && atol > 0, prefix + "atol", atol, "an absolute tolerance > 0");
  require(std::isfinite(max_step) && max_step >= 0, prefix + "max_step", max_step,
          "a finite step >= 0 s (0 = the contact interval dt)");
  require(linear_solver == "auto" || linear_solver == "cg" || linear_solver == "gmres" ||
              linear_solver == "jacobi" || linear_solver == "schur" || linear_solver == "klu",
          prefix + "linear_solver", "\"" + linear_solver + "\"",
          "one of \"auto\", \"cg\", \"gmres\", \"jacobi\", \"schur\", \"klu\"");
  require(max_steps > 0, prefix + "max_steps", max_steps,
          "a number of internal steps per contact interval > 0");
}

ArkodeOptions ArkodeOptions::read(JsonFields& f) {
  ArkodeOptions o;
  o.rtol = f.number_or("rtol", o.rtol);
  o.atol = f.number_or("atol", o.atol);
  o.method = f.string_or("method", o.method);
  o.max_step = f.number_or("max_step", o.max_step);
  o.linear_solver = f.string_or("linear_solver", o.linear_solver);
  o.max_steps = f.long_or("max_steps", o.max_steps);
  o.validate(f.prefix());
  return o;
}

Json ArkodeOptions::to_json() const {
  Json out = Json::object();
  out["rtol"] = rtol;
  out["atol"] = atol;
  out["method"] = method;
  out["max_step"] = max_step;
  out["linear_solver"] = linear_solver;
  out["max_steps"] = max_steps;
  return out;
}

}  // namespace jelly
