#pragma once
// Adaptive implicit DIRK through SUNDIALS ARKODE's ARKStep (implicit part only, the full
// right-hand side) with Newton iterations whose linear systems are solved by the Schur
// reduction to the SPD M - gamma D - gamma^2 K ("schur", default) or by KLU on the sparse 6N
// Jacobian ("klu"). Each step() integrates adaptively over the Simulator's dt (docs/arkode.md).
#include <memory>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

namespace arkode {
class Driver;
}

class ArkodeDirk final : public Integrator {
 public:
  static constexpr const char* kDefaultMethod = "ARKODE_ARK548L2SA_DIRK_8_4_5";

  // Throws InputError for an invalid option or a method name that is not an embedded DIRK table.
  explicit ArkodeDirk(const ArkodeOptions& options = {});
  ~ArkodeDirk() override;

  std::string_view name() const override { return "arkode_dirk"; }
  int order() const override { return order_; }
  bool is_implicit() const override { return true; }
  bool is_adaptive() const override { return true; }
  // With the linear solvers "cg", "jacobi" (the added forces' Jacobians in their operator and
  // block diagonal) and "gmres" (products from the right-hand side, the blocks in its
  // preconditioner); "schur" and "klu" keep the springs' fixed pattern and leave them out of
  // the Newton matrix (the forces stay in the implicit stages: Newton converges more slowly).
  bool uses_force_jacobians() const override { return uses_force_jacobians_; }
  // "steps" plus ARKODE's counters (as arkode_erk) and newton_iterations,
  // newton_convergence_failures, linear_setups, and for "schur" schur_factorizations,
  // schur_not_positive_definite; for "klu" jacobian_evaluations.
  Statistics statistics() const override;

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  std::unique_ptr<arkode::Driver> driver_;
  int order_ = 0;
  bool uses_force_jacobians_ = false;
};

}  // namespace jelly
