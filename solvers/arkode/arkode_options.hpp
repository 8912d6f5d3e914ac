#pragma once
// Options of the adaptive SUNDIALS ARKODE integrators (arkode_erk, arkode_dirk; docs/arkode.md).
#include <string>

#include <jelly/core/json.hpp>
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

  // Throws InputError "<prefix><field> = <value> is invalid: ..." for the first invalid field
  // (prefix e.g. "integrator.options."). The method name is checked by the integrator using it.
  void validate(const std::string& prefix) const;
  // The scene's integrator.options of arkode_erk and arkode_dirk, validated with their paths.
  static ArkodeOptions read(JsonFields& fields);
  Json to_json() const;
};

}  // namespace jelly
