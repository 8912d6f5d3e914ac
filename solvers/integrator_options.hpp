#pragma once
// Options for the integrators that take any; the explicit methods take none.
#include <string>

#include <jelly/core/types.hpp>

namespace jelly {

struct IntegratorOptions {
  // Throws InputError naming the first invalid option.
  void validate() const {}
};

}  // namespace jelly
