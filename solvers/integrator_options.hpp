#pragma once
// Options for the integrators that take any; the explicit methods take none.
#include <string>

#include <jelly/core/types.hpp>
#include <jelly/solvers/arkode_options.hpp>

namespace jelly {

struct IntegratorOptions {
  ArkodeOptions arkode;  // arkode_erk, arkode_dirk

  // Throws InputError naming the first invalid option.
  void validate() const { arkode.validate(); }
};

}  // namespace jelly
