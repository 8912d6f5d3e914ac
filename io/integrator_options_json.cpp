#include <jelly/io/detail/integrator_options_json.hpp>

namespace jelly::detail {

IntegratorOptions parse_integrator_options(const Json& options, const std::string& path) {
  JsonFields fields(options, path);
  IntegratorOptions out;
  // ---- Integrator option fields are read here, one line each, with the struct's defaults:
  //        out.newton_iterations = fields.integer_or("newton_iterations", out.newton_iterations);
  //      (the implicit Euler and ARKODE options go here when IntegratorOptions gains them).
  //      Unknown keys stay errors (reject_unknown below). For range errors to name the JSON path
  //      ("integrator.options.newton_iterations"), give IntegratorOptions::validate a prefix
  //      parameter like ContactParams::validate and pass path + "." here and in Scene::validate.
  // ----
  fields.reject_unknown();
  out.validate();
  return out;
}

Json integrator_options_to_json(const IntegratorOptions& /*options*/) {
  Json out = Json::object();
  // ---- Write every IntegratorOptions field here, matching parse_integrator_options:
  //        out["newton_iterations"] = options.newton_iterations;
  // ----
  return out;
}

}  // namespace jelly::detail
