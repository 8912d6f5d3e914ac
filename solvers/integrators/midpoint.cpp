#include <jelly/solvers/integrators/detail/midpoint.hpp>

namespace jelly {

StepResult Midpoint::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Eigen::Index n = s.x.size();
  ensure_size(a_, n);
  ensure_size(x_mid_, n);
  ensure_size(v_mid_, n);
  dynamics.stage_acceleration(s.t, s.x, s.v, a_);
  x_mid_ = s.x + (0.5 * h) * s.v;
  v_mid_ = s.v + (0.5 * h) * a_;
  // With seed_framework the half step's evaluation may reflect v_mid, which then moves x.
  dynamics.stage_acceleration(s.t + 0.5 * h, x_mid_, v_mid_, a_);
  s.x += h * v_mid_;
  s.v += h * a_;
  s.t += h;
  return StepResult::success();
}

}  // namespace jelly
