#pragma once
// Adaptive explicit Runge-Kutta through SUNDIALS ARKODE's ERKStep on y = [x; v], with an
// embedded pair chosen by name (default Dormand-Prince 5(4)). Each step() integrates adaptively
// over the Simulator's dt, the contact-check interval (docs/arkode.md).
#include <memory>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

namespace arkode {
class Driver;
}

class ArkodeErk final : public Integrator {
 public:
  static constexpr const char* kDefaultMethod = "ARKODE_DORMAND_PRINCE_7_4_5";

  // Throws InputError for an invalid option or a method name that is not an embedded ERK table.
  explicit ArkodeErk(const ArkodeOptions& options = {});
  ~ArkodeErk() override;

  std::string_view name() const override { return "arkode_erk"; }
  // The order of the method's main formula (5 for Dormand-Prince).
  int order() const override { return order_; }
  bool is_adaptive() const override { return true; }
  // "steps" (contact intervals) plus ARKODE's counters: arkode_steps, arkode_step_attempts,
  // arkode_error_test_failures, rhs_evaluations, arkode_resets.
  Statistics statistics() const override;
  int stages() const { return stages_; }

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  std::unique_ptr<arkode::Driver> driver_;
  int order_ = 0, stages_ = 0;
};

}  // namespace jelly
