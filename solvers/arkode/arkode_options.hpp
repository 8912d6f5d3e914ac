#pragma once
// Options of the adaptive SUNDIALS ARKODE integrators (arkode_erk, arkode_dirk; docs/arkode.md).
#include <string>

#include <jelly/core/types.hpp>

namespace jelly {

struct ArkodeOptions {
  Real rtol = 1e-6;  // relative tolerance of the local error test, in (0, 1)
  Real atol = 1e-8;  // absolute tolerance (m and m/s), > 0
  // An ARKODE Butcher table name with an embedding ("ARKODE_DORMAND_PRINCE_7_4_5" for
  // arkode_erk, "ARKODE_ARK548L2SA_DIRK_8_4_5" for arkode_dirk); empty = that default.
  std::string method;
  Real max_step = 0;                    // s, largest internal step; 0 = the contact interval dt
  std::string linear_solver = "schur";  // arkode_dirk: "schur" (default) or "klu"
  long max_steps = 100000;              // internal steps per contact interval, > 0

  // Throws InputError naming the first invalid field (integrator.options.<field>). The method
  // name is checked by the integrator that uses it.
  void validate() const;
};

}  // namespace jelly
