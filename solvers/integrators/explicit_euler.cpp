#include <jelly/solvers/integrators/detail/explicit_euler.hpp>

namespace jelly {

StepResult ExplicitEuler::do_step(const Dynamics& dynamics, State& s, Real h) {
  ensure_size(a_, s.x.size());
  dynamics.stage_acceleration(s.t, s.x, s.v, a_);
  s.x += h * s.v;
  s.v += h * a_;
  s.t += h;
  return StepResult::success();
}

}  // namespace jelly
