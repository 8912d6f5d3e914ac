#include <jelly/core/components.hpp>

#include <memory>
#include <string>

#include <jelly/core/detail/field_table.hpp>
#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/arkode/detail/arkode_dirk.hpp>
#include <jelly/solvers/arkode/detail/arkode_erk.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>
#include <jelly/solvers/integrators/detail/options_io.hpp>
#include <jelly/solvers/integrators/registry.hpp>

// The arkode component (SUNDIALS): its two integrators, registered in the integrator table.
namespace jelly {

namespace {

constexpr auto kArkodeMember = &IntegratorOptions::arkode;

// arkode_erk's options: ArkodeOptions without arkode_dirk's linear solver.
IntegratorOptionsIo arkode_erk_options() {
  IntegratorOptionsIo io = detail::options_io<kArkodeMember>();
  io.validate = [](const IntegratorOptions& o, const std::string& prefix) {
    o.arkode.validate(prefix);
    require(o.arkode.linear_solver == ArkodeLinearSolver::kAuto, prefix + "linear_solver",
            "\"" + std::string(name_of(arkode_linear_solvers(), o.arkode.linear_solver)) + "\"",
            "\"auto\" (arkode_erk solves no linear system: linear_solver is arkode_dirk's "
            "option)");
  };
  return io;
}

}  // namespace

void register_arkode_component() {
  if (has_component("arkode")) return;
  component_field_documents().push_back([] {
    return document_fields(arkode_fields(), {"arkode_erk", "arkode_dirk"});
  });
  register_component({"arkode", "SUNDIALS ARKODE adaptive integrators (arkode_dirk, arkode_erk)"});
  register_integrator(
      {"arkode_dirk", "SUNDIALS ARKODE adaptive implicit DIRK (Newton, Schur or KLU linear solves)",
       detail::options_io<kArkodeMember>()},
      [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
        return std::make_unique<ArkodeDirk>(o.arkode);
      });
  register_integrator(
      {"arkode_erk", "SUNDIALS ARKODE adaptive explicit Runge-Kutta (default 5(4) pair)",
       arkode_erk_options()},
      [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
        return std::make_unique<ArkodeErk>(o.arkode);
      });
}

}  // namespace jelly
