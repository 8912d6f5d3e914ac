#include <jelly/io/detail/integrator_options_json.hpp>

#include <jelly/core/errors.hpp>

namespace jelly::detail {

namespace {

bool uses_implicit_options(const std::string& integrator) { return integrator == "implicit_euler"; }
bool uses_arkode_options(const std::string& integrator) {
  return integrator.rfind("arkode_", 0) == 0;
}

void parse_implicit(JsonFields& f, ImplicitEulerOptions& o) {
  o.newton_iterations = f.integer_or("newton_iterations", o.newton_iterations);
  o.newton_tolerance = f.number_or("newton_tolerance", o.newton_tolerance);
  const std::string fix =
      f.string_or("definiteness", std::string(definiteness_name(o.definiteness)));
  require(parse_definiteness(fix, &o.definiteness), f.path("definiteness"), "\"" + fix + "\"",
          "one of \"clamp\", \"project\", \"none\"");
  o.linear_solver = f.string_or("linear_solver", o.linear_solver);
  o.cg_preconditioner = f.string_or("cg_preconditioner", o.cg_preconditioner);
  o.cg_tolerance = f.number_or("cg_tolerance", o.cg_tolerance);
  o.cg_max_iterations = f.integer_or("cg_max_iterations", o.cg_max_iterations);
  o.refactor_iterations = f.integer_or("refactor_iterations", o.refactor_iterations);
  o.ordering = f.string_or("ordering", o.ordering);
  o.contact = f.string_or("contact", o.contact);
  o.contact_iterations = f.integer_or("contact_iterations", o.contact_iterations);
}

void parse_arkode(JsonFields& f, ArkodeOptions& o) {
  o.rtol = f.number_or("rtol", o.rtol);
  o.atol = f.number_or("atol", o.atol);
  o.method = f.string_or("method", o.method);
  o.max_step = f.number_or("max_step", o.max_step);
  o.linear_solver = f.string_or("linear_solver", o.linear_solver);
  o.max_steps = f.long_or("max_steps", o.max_steps);
}

}  // namespace

IntegratorOptions parse_integrator_options(const Json& options, const std::string& path,
                                           const std::string& integrator) {
  JsonFields fields(options, path);
  IntegratorOptions out;
  if (uses_implicit_options(integrator)) parse_implicit(fields, out.implicit);
  if (uses_arkode_options(integrator)) parse_arkode(fields, out.arkode);
  fields.reject_unknown();
  out.validate();
  return out;
}

Json integrator_options_to_json(const IntegratorOptions& options, const std::string& integrator) {
  Json out = Json::object();
  if (uses_implicit_options(integrator)) {
    const ImplicitEulerOptions& o = options.implicit;
    out["newton_iterations"] = o.newton_iterations;
    out["newton_tolerance"] = o.newton_tolerance;
    out["definiteness"] = std::string(definiteness_name(o.definiteness));
    out["linear_solver"] = o.linear_solver;
    out["cg_preconditioner"] = o.cg_preconditioner;
    out["cg_tolerance"] = o.cg_tolerance;
    out["cg_max_iterations"] = o.cg_max_iterations;
    out["refactor_iterations"] = o.refactor_iterations;
    out["ordering"] = o.ordering;
    out["contact"] = o.contact;
    out["contact_iterations"] = o.contact_iterations;
  }
  if (uses_arkode_options(integrator)) {
    const ArkodeOptions& o = options.arkode;
    out["rtol"] = o.rtol;
    out["atol"] = o.atol;
    out["method"] = o.method;
    out["max_step"] = o.max_step;
    out["linear_solver"] = o.linear_solver;
    out["max_steps"] = o.max_steps;
  }
  return out;
}

}  // namespace jelly::detail
