#include <jelly/solvers/integrators/integrator_options.hpp>

#include <cmath>

#include <arkode/arkode_butcher_dirk.h>
#include <arkode/arkode_butcher_erk.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>

namespace jelly {

const std::vector<EnumName<ArkodeLinearSolver>>& arkode_linear_solvers() {
  static const std::vector<EnumName<ArkodeLinearSolver>> table{
      {ArkodeLinearSolver::kAuto, "auto", "the fastest measured (docs/arkode.md): cg"},
      {ArkodeLinearSolver::kCg, "cg", "Schur reduction, matrix-free block-Jacobi CG"},
      {ArkodeLinearSolver::kJacobi, "jacobi", "the block diagonal of the Newton matrix"},
      {ArkodeLinearSolver::kGmres, "gmres", "SUNDIALS SPGMR, block-Jacobi preconditioned"},
      {ArkodeLinearSolver::kSchur, "schur", "Schur reduction factorized by CHOLMOD"},
      {ArkodeLinearSolver::kKlu, "klu", "SUNDIALS KLU on the 6N Jacobian"},
  };
  return table;
}

const std::vector<EnumName<int>>& arkode_erk_methods() {
  static const std::vector<EnumName<int>> table{
      {ARKODE_HEUN_EULER_2_1_2, "ARKODE_HEUN_EULER_2_1_2", "2 stages, order 2 (1)"},
      {ARKODE_BOGACKI_SHAMPINE_4_2_3, "ARKODE_BOGACKI_SHAMPINE_4_2_3", "4 stages, order 3 (2)"},
      {ARKODE_ARK324L2SA_ERK_4_2_3, "ARKODE_ARK324L2SA_ERK_4_2_3", "4 stages, order 3 (2)"},
      {ARKODE_ZONNEVELD_5_3_4, "ARKODE_ZONNEVELD_5_3_4", "5 stages, order 4 (3)"},
      {ARKODE_ARK436L2SA_ERK_6_3_4, "ARKODE_ARK436L2SA_ERK_6_3_4", "6 stages, order 4 (3)"},
      {ARKODE_SAYFY_ABURUB_6_3_4, "ARKODE_SAYFY_ABURUB_6_3_4", "6 stages, order 4 (3)"},
      {ARKODE_CASH_KARP_6_4_5, "ARKODE_CASH_KARP_6_4_5", "6 stages, order 5 (4)"},
      {ARKODE_FEHLBERG_6_4_5, "ARKODE_FEHLBERG_6_4_5", "6 stages, order 5 (4)"},
      {ARKODE_DORMAND_PRINCE_7_4_5, "ARKODE_DORMAND_PRINCE_7_4_5",
       "7 stages, order 5 (4), first same as last: arkode_erk's default"},
      {ARKODE_ARK548L2SA_ERK_8_4_5, "ARKODE_ARK548L2SA_ERK_8_4_5", "8 stages, order 5 (4)"},
      {ARKODE_VERNER_8_5_6, "ARKODE_VERNER_8_5_6", "8 stages, order 6 (5)"},
      {ARKODE_FEHLBERG_13_7_8, "ARKODE_FEHLBERG_13_7_8", "13 stages, order 8 (7)"},
      {ARKODE_ARK437L2SA_ERK_7_3_4, "ARKODE_ARK437L2SA_ERK_7_3_4", "7 stages, order 4 (3)"},
      {ARKODE_ARK548L2SAb_ERK_8_4_5, "ARKODE_ARK548L2SAb_ERK_8_4_5", "8 stages, order 5 (4)"},
  };
  return table;
}

const std::vector<EnumName<int>>& arkode_dirk_methods() {
  static const std::vector<EnumName<int>> table{
      {ARKODE_SDIRK_2_1_2, "ARKODE_SDIRK_2_1_2", "2 stages, order 2 (1)"},
      {ARKODE_BILLINGTON_3_3_2, "ARKODE_BILLINGTON_3_3_2", "3 stages, order 2 (3)"},
      {ARKODE_TRBDF2_3_3_2, "ARKODE_TRBDF2_3_3_2", "3 stages, order 2 (3)"},
      {ARKODE_KVAERNO_4_2_3, "ARKODE_KVAERNO_4_2_3", "4 stages, order 3 (2)"},
      {ARKODE_ARK324L2SA_DIRK_4_2_3, "ARKODE_ARK324L2SA_DIRK_4_2_3", "4 stages, order 3 (2)"},
      {ARKODE_CASH_5_2_4, "ARKODE_CASH_5_2_4", "5 stages, order 4 (2)"},
      {ARKODE_CASH_5_3_4, "ARKODE_CASH_5_3_4", "5 stages, order 4 (3)"},
      {ARKODE_SDIRK_5_3_4, "ARKODE_SDIRK_5_3_4", "5 stages, order 4 (3)"},
      {ARKODE_KVAERNO_5_3_4, "ARKODE_KVAERNO_5_3_4", "5 stages, order 4 (3)"},
      {ARKODE_ARK436L2SA_DIRK_6_3_4, "ARKODE_ARK436L2SA_DIRK_6_3_4", "6 stages, order 4 (3)"},
      {ARKODE_KVAERNO_7_4_5, "ARKODE_KVAERNO_7_4_5", "7 stages, order 5 (4)"},
      {ARKODE_ARK548L2SA_DIRK_8_4_5, "ARKODE_ARK548L2SA_DIRK_8_4_5",
       "8 stages, order 5 (4), L-stable: arkode_dirk's default"},
      {ARKODE_ARK437L2SA_DIRK_7_3_4, "ARKODE_ARK437L2SA_DIRK_7_3_4", "7 stages, order 4 (3)"},
      {ARKODE_ARK548L2SAb_DIRK_8_4_5, "ARKODE_ARK548L2SAb_DIRK_8_4_5", "8 stages, order 5 (4)"},
      {ARKODE_ESDIRK324L2SA_4_2_3, "ARKODE_ESDIRK324L2SA_4_2_3", "4 stages, order 3 (2)"},
      {ARKODE_ESDIRK325L2SA_5_2_3, "ARKODE_ESDIRK325L2SA_5_2_3", "5 stages, order 3 (2)"},
      {ARKODE_ESDIRK32I5L2SA_5_2_3, "ARKODE_ESDIRK32I5L2SA_5_2_3", "5 stages, order 3 (2)"},
      {ARKODE_ESDIRK436L2SA_6_3_4, "ARKODE_ESDIRK436L2SA_6_3_4", "6 stages, order 4 (3)"},
      {ARKODE_ESDIRK43I6L2SA_6_3_4, "ARKODE_ESDIRK43I6L2SA_6_3_4", "6 stages, order 4 (3)"},
      {ARKODE_QESDIRK436L2SA_6_3_4, "ARKODE_QESDIRK436L2SA_6_3_4", "6 stages, order 4 (3)"},
      {ARKODE_ESDIRK437L2SA_7_3_4, "ARKODE_ESDIRK437L2SA_7_3_4", "7 stages, order 4 (3)"},
      {ARKODE_ESDIRK547L2SA_7_4_5, "ARKODE_ESDIRK547L2SA_7_4_5", "7 stages, order 5 (4)"},
      {ARKODE_ESDIRK547L2SA2_7_4_5, "ARKODE_ESDIRK547L2SA2_7_4_5", "7 stages, order 5 (4)"},
  };
  return table;
}

int arkode_method_id(const std::vector<EnumName<int>>& table, const std::string& method,
                     const std::string& default_method) {
  return value_of(table, method.empty() ? default_method : method, "integrator.options.method");
}

const FieldTable<ArkodeOptions>& arkode_fields() {
  using O = ArkodeOptions;
  static const FieldTable<O> table{
      "ArkodeOptions",
      "integrator.options",
      "Options of arkode_erk and arkode_dirk (docs/arkode.md)",
      {
          number_field<&O::rtol>("rtol", "", range_open(0, 1), "a relative tolerance in (0, 1)",
                                 "Relative tolerance of the local error test"),
          number_field<&O::atol>("atol", "m, m/s", range_above(0), "an absolute tolerance > 0",
                                 "Absolute tolerance of the local error test"),
          string_field<&O::method>(
              "method", "an ARKODE Butcher table name of the integrator (jelly list)",
              "An ARKODE Butcher table name; empty = the integrator's default"),
          number_field<&O::max_step>("max_step", "s", range_at_least(0),
                                     "a finite step >= 0 s (0 = the contact interval dt)",
                                     "Largest internal step; 0 = the contact interval dt"),
          choice_field<&O::linear_solver, &arkode_linear_solvers>(
              "linear_solver", "How arkode_dirk solves its Newton systems (arkode_dirk only)"),
          integer_field<&O::max_steps>("max_steps", "", range_above(0),
                                       "a number of internal steps per contact interval > 0",
                                       "Internal steps per contact interval at most"),
      },
  };
  return table;
}

void ArkodeOptions::validate(const std::string& prefix) const {
  validate_fields(arkode_fields(), *this, prefix);
}

ArkodeOptions ArkodeOptions::read(JsonFields& f) {
  ArkodeOptions o;
  read_fields(arkode_fields(), f, o, f.prefix());
  return o;
}

Json ArkodeOptions::to_json() const {
  Json out = Json::object();
  write_fields(arkode_fields(), *this, out);
  return out;
}

}  // namespace jelly
