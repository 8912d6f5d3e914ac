#pragma once
// Forward Euler: x' = x + h v, v' = v + h a(x, v).
#include <jelly/solvers/integrators/integrator.hpp>

namespace jelly {

class ExplicitEuler final : public Integrator {
 public:
  std::string_view name() const override { return "explicit_euler"; }
  int order() const override { return 1; }
  // Every force evaluation goes through Dynamics::stage_acceleration().

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  VecX a_;
};

}  // namespace jelly
