#pragma once
// Options of the adaptive SUNDIALS ARKODE integrators (arkode_erk, arkode_dirk; docs/arkode.md).
#include <string>
#include <vector>

#include <jelly/core/enum_names.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

// How arkode_dirk solves its Newton systems (docs/arkode.md, "The Newton systems").
enum class ArkodeLinearSolver {
  kAuto,    // the fastest in every measurement of docs/arkode.md: kCg
  kCg,      // Schur reduction solved matrix-free by block-Jacobi preconditioned CG
  kJacobi,  // the Newton matrix's 3x3 block diagonal alone (a modified Newton)
  kGmres,   // SUNDIALS' SPGMR on the 6N system, block-Jacobi preconditioned
  kSchur,   // Schur reduction factorized by CHOLMOD at each setup
  kKlu,     // SUNDIALS' KLU on the 6N Jacobian (to check the others)
};
const std::vector<EnumName<ArkodeLinearSolver>>& arkode_linear_solvers();

// The ARKODE Butcher tables with an embedding (an error estimate), by the names ARKODE gives
// them; the value is ARKODE's table id. Explicit ones for arkode_erk, diagonally implicit ones
// for arkode_dirk.
const std::vector<EnumName<int>>& arkode_erk_methods();
const std::vector<EnumName<int>>& arkode_dirk_methods();

struct ArkodeOptions {
  Real rtol = 1e-6;  // relative tolerance of the local error test, in (0, 1)
  Real atol = 1e-8;  // absolute tolerance (m and m/s), > 0
  // A name of arkode_erk_methods() or arkode_dirk_methods() (which depends on the integrator:
  // "ARKODE_DORMAND_PRINCE_7_4_5" for arkode_erk, "ARKODE_ARK548L2SA_DIRK_8_4_5" for
  // arkode_dirk); empty = that default.
  std::string method;
  Real max_step = 0;  // s, largest internal step; 0 = the contact interval dt
  ArkodeLinearSolver linear_solver = ArkodeLinearSolver::kAuto;  // arkode_dirk only
  long max_steps = 100000;  // internal steps per contact interval, > 0

  // Throws InputError "<prefix><field> = <value> is invalid: ..." for the first invalid field
  // (prefix e.g. "integrator.options."). The method name is checked by the integrator using it
  // (arkode_method_id).
  void validate(const std::string& prefix) const;
  // The scene's integrator.options of arkode_erk and arkode_dirk, validated with their paths.
  static ArkodeOptions read(JsonFields& fields);
  Json to_json() const;
};

// The ARKODE table id of `method` in `table` (empty: `default_method`); throws InputError naming
// integrator.options.method with the table's names for another name.
int arkode_method_id(const std::vector<EnumName<int>>& table, const std::string& method,
                     const std::string& default_method);

}  // namespace jelly
