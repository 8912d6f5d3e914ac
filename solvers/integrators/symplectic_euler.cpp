#include <jelly/solvers/integrators/detail/symplectic_euler.hpp>

namespace jelly {

StepResult SymplecticEuler::do_step(const Dynamics& dynamics, State& s, Real h) {
  ensure_size(a_, s.x.size());
  dynamics.stage_acceleration(s.t, s.x, s.v, a_);
  s.v += h * a_;
  s.x += h * s.v;
  s.t += h;
  return StepResult::success();
}

}  // namespace jelly
