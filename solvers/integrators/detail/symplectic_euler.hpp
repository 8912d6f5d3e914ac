#pragma once
// Semi-implicit (symplectic) Euler: v' = v + h a(x, v), x' = x + h v'. This is what the seed
// report called "implicit Euler": it re-evaluated forces but never solved a system.
#include <jelly/solvers/integrators/integrator.hpp>

namespace jelly {

class SymplecticEuler final : public Integrator {
 public:
  std::string_view name() const override { return "symplectic_euler"; }
  int order() const override { return 1; }
  // Every force evaluation goes through Dynamics::stage_acceleration().

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  VecX a_;
};

}  // namespace jelly
