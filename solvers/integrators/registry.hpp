#pragma once
// Integrators by name, from one sorted table: each entry says what the integrator is, how to
// make it, and which options it takes in a scene (integrator.options). The core's integrators
// are in it from the start; a component's (arkode) only in a program that links the component.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

// The options of one integrator, as a scene holds them: read (validated, messages naming the
// fields' JSON paths) into its member of IntegratorOptions, written back, validated. All null for
// an integrator that takes none.
struct IntegratorOptionsIo {
  // Reads the method's keys from `fields` into `options`.
  void (*read)(JsonFields& fields, IntegratorOptions& options) = nullptr;
  // Writes the method's keys.
  Json (*write)(const IntegratorOptions& options) = nullptr;
  // Throws InputError naming `prefix`field for a value out of range.
  void (*validate)(const IntegratorOptions& options, const std::string& prefix) = nullptr;
};

// One integrator of the registry: its name, description, options and what contact it supports.
struct IntegratorInfo {
  std::string_view name;         // "rk4", "implicit_euler", ...
  std::string_view description;  // one line
  IntegratorOptionsIo options;   // how its options are read, written and validated
  // True when every force evaluation of the method's step goes through
  // Dynamics::stage_acceleration(), so that the models acting inside evaluations
  // (seed_framework) work with it (the explicit methods). The others refuse such terrains: a
  // velocity reflection inside an implicit solve's or ARKODE's right-hand side is not a function
  // of the state they iterate on (docs/contact.md).
  bool in_evaluation_contact = false;
};

// Makes an integrator from the options (validated before it is called).
using IntegratorFactory = std::unique_ptr<Integrator> (*)(const IntegratorOptions& options);

// Adds an integrator to the table (a name already there is left as it was): how a component
// (arkode) registers its kinds (core/components.hpp). Before main or before any other thread
// reads the table: the references integrator_infos() returned before are invalidated.
void register_integrator(const IntegratorInfo& info, IntegratorFactory make);

// Every registered integrator, sorted by name.
const std::vector<IntegratorInfo>& integrator_infos();
std::vector<std::string> integrator_names();  // the names of integrator_infos(), sorted
// The registered integrator's IntegratorInfo::in_evaluation_contact; false for a name the
// registry does not know (an integrator of the user's own that was not registered).
bool integrator_supports_in_evaluation_contact(std::string_view name);
// Throws InputError "<field> = "rk5" is invalid: one of ..." for an unknown name.
const IntegratorInfo& find_integrator(std::string_view name,
                                      std::string_view field = "integrator.name");
// The integrator's options from a scene's integrator.options (`fields`); the keys of another
// integrator are left unread (JsonFields::reject_unknown then names them).
IntegratorOptions read_integrator_options(std::string_view name, JsonFields& fields);
// Its options as a scene writes them ({} for an integrator without options).
Json integrator_options_json(std::string_view name, const IntegratorOptions& options);
// Validates the options the named integrator uses (InputError naming `options_path`.<field>)
// and makes it.
std::unique_ptr<Integrator> make_integrator(std::string_view name,
                                            const IntegratorOptions& options = {},
                                            std::string_view options_path = "integrator.options");

}  // namespace jelly
