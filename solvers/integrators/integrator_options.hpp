#pragma once
// Options for the integrators that take any; the explicit methods take none.
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/core/types.hpp>
#include <jelly/solvers/arkode/arkode_options.hpp>
#include <jelly/solvers/integrators/implicit_euler_options.hpp>

namespace jelly {

struct IntegratorOptions {
  ImplicitEulerOptions implicit;  // implicit_euler
  ArkodeOptions arkode;           // arkode_erk, arkode_dirk

  // Throws InputError naming the first invalid option as the scene path
  // "integrator.options.<field>" (docs/scenes.md).
  void validate() const {
    std::string why;
    if (!implicit.is_valid(&why)) throw InputError("integrator." + why);
    arkode.validate();
  }
};

}  // namespace jelly
