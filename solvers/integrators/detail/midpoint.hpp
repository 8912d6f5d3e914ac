#pragma once
// Explicit midpoint (the report's midpoint Euler): half a step with a(x, v), then the full step
// with the velocity and acceleration at the midpoint.
#include <jelly/solvers/integrators/integrator.hpp>

namespace jelly {

class Midpoint final : public Integrator {
 public:
  std::string_view name() const override { return "midpoint"; }
  int order() const override { return 2; }
  // Every force evaluation goes through Dynamics::stage_acceleration().

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  VecX a_, x_mid_, v_mid_;
};

}  // namespace jelly
