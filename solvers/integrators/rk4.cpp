#include <jelly/solvers/integrators/rk4.hpp>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

StepResult RungeKutta4::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Eigen::Index n = s.x.size();
  for (VecX* w : {&a_, &x_stage_, &v_stage_, &dx_, &dv_}) ensure_size(*w, n);
  Real* x = s.x.data();
  Real* v = s.v.data();
  Real* a = a_.data();
  Real* xs = x_stage_.data();
  Real* vs = v_stage_.data();
  Real* dx = dx_.data();
  Real* dv = dv_.data();
  const Real half = 0.5 * h, sixth = h / 6;
  // The vector updates between the stages, one threaded pass each (element-wise: the same bits
  // for any thread count).
  const auto pass = [&](auto&& body) {
    parallel::for_ranges(dynamics.threads(), n, [&](long begin, long end) {
      for (long i = begin; i < end; ++i) body(i);
    });
  };
  // Each stage's dx/dt is its velocity after its own evaluation, which a seed_framework terrain
  // may reflect (stage 1: the step's own velocity, as in the course framework).
  // Stage 1; then stage 2 at y + h/2 k1.
  dynamics.stage_acceleration(s.t, s.x, s.v, a_);
  pass([&](long i) {
    dx[i] = v[i];
    dv[i] = a[i];
    xs[i] = x[i] + half * v[i];
    vs[i] = v[i] + half * a[i];
  });
  // After stage 2 (3): its slope into the sum, and stage 3 (4) at y + c k2 (k3), c = h/2 (h).
  const auto next_stage = [&](Real c) {
    pass([&](long i) {
      dx[i] += 2 * vs[i];
      dv[i] += 2 * a[i];
      xs[i] = x[i] + c * vs[i];
      vs[i] = v[i] + c * a[i];
    });
  };
  dynamics.stage_acceleration(s.t + half, x_stage_, v_stage_, a_);
  next_stage(half);
  dynamics.stage_acceleration(s.t + half, x_stage_, v_stage_, a_);
  next_stage(h);
  dynamics.stage_acceleration(s.t + h, x_stage_, v_stage_, a_);
  pass([&](long i) {
    dx[i] += vs[i];
    dv[i] += a[i];
    x[i] += sixth * dx[i];
    v[i] += sixth * dv[i];
  });
  s.t += h;
  return StepResult::success();
}

}  // namespace jelly
