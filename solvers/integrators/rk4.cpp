#include <jelly/solvers/integrators/rk4.hpp>

namespace jelly {

StepResult RungeKutta4::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Eigen::Index n = s.x.size();
  for (VecX* w : {&a_, &x_stage_, &v_stage_, &dx_, &dv_}) ensure_size(*w, n);
  // Each stage's dx/dt is its velocity after its own evaluation, which a seed_framework terrain
  // may reflect (stage 1: the step's own velocity, as in the course framework).
  // Stage 1.
  dynamics.stage_acceleration(s.t, s.x, s.v, a_);
  dx_ = s.v;
  dv_ = a_;
  // Stage 2, at y + h/2 k1.
  x_stage_ = s.x + (0.5 * h) * s.v;
  v_stage_ = s.v + (0.5 * h) * a_;
  dynamics.stage_acceleration(s.t + 0.5 * h, x_stage_, v_stage_, a_);
  dx_ += 2 * v_stage_;
  dv_ += 2 * a_;
  // Stage 3, at y + h/2 k2.
  x_stage_ = s.x + (0.5 * h) * v_stage_;
  v_stage_ = s.v + (0.5 * h) * a_;
  dynamics.stage_acceleration(s.t + 0.5 * h, x_stage_, v_stage_, a_);
  dx_ += 2 * v_stage_;
  dv_ += 2 * a_;
  // Stage 4, at y + h k3.
  x_stage_ = s.x + h * v_stage_;
  v_stage_ = s.v + h * a_;
  dynamics.stage_acceleration(s.t + h, x_stage_, v_stage_, a_);
  dx_ += v_stage_;
  dv_ += a_;
  s.x += (h / 6) * dx_;
  s.v += (h / 6) * dv_;
  s.t += h;
  return StepResult::success();
}

}  // namespace jelly
