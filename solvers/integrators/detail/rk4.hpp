#pragma once
// Classical fourth-order Runge-Kutta on the first-order system y = (x, v), y' = (v, a(x, v)).
#include <jelly/solvers/integrators/integrator.hpp>

namespace jelly {

class RungeKutta4 final : public Integrator {
 public:
  std::string_view name() const override { return "rk4"; }
  int order() const override { return 4; }
  // Every force evaluation goes through Dynamics::stage_acceleration().

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  VecX a_, x_stage_, v_stage_, dx_, dv_;
};

}  // namespace jelly
