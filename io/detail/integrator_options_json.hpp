#pragma once
// The "integrator.options" object of a scene <-> IntegratorOptions. Internal to io/.
#include <string>

#include <jelly/core/json.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly::detail {

// Fills IntegratorOptions from the JSON object at `path` ("integrator.options"). The keys are
// those of the named integrator: implicit_euler reads ImplicitEulerOptions, arkode_* read
// ArkodeOptions, the others take none. An unknown key, a wrong type or an invalid value is an
// InputError naming its path.
IntegratorOptions parse_integrator_options(const Json& options, const std::string& path,
                                           const std::string& integrator);
// The options of the named integrator written out, so that parse_integrator_options reads back
// equal options.
Json integrator_options_to_json(const IntegratorOptions& options, const std::string& integrator);

}  // namespace jelly::detail
