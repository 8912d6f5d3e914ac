#include <jelly/solvers/integrators/detail/rk4.hpp>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

namespace {

// The vector updates between the stages over entries [begin, end), element-wise: the same bits
// for any thread count. x, v: the step's state; a: the last stage's acceleration; xs, vs: the
// next stage's state; dx, dv: the weighted sums of the slopes. Distinct arrays (restrict
// parameters: GCC vectorises the loops then; restrict locals copied from a struct it did not).

// After stage 1: its slope, and stage 2 at y + h/2 k1.
void first_stage(long begin, long end, Real half, Real* __restrict x, Real* __restrict v,
                 const Real* __restrict a, Real* __restrict xs, Real* __restrict vs,
                 Real* __restrict dx, Real* __restrict dv) {
  for (long i = begin; i < end; ++i) {
    dx[i] = v[i];
    dv[i] = a[i];
    xs[i] = x[i] + half * v[i];
    vs[i] = v[i] + half * a[i];
  }
}

// After stage 2 (3): its slope into the sum, and stage 3 (4) at y + c k2 (k3).
void next_stage(long begin, long end, Real c, Real* __restrict x, Real* __restrict v,
                const Real* __restrict a, Real* __restrict xs, Real* __restrict vs,
                Real* __restrict dx, Real* __restrict dv) {
  for (long i = begin; i < end; ++i) {
    dx[i] += 2 * vs[i];
    dv[i] += 2 * a[i];
    xs[i] = x[i] + c * vs[i];
    vs[i] = v[i] + c * a[i];
  }
}

// After stage 4: the step.
void last_stage(long begin, long end, Real sixth, Real* __restrict x, Real* __restrict v,
                const Real* __restrict a, Real* __restrict /*xs*/, Real* __restrict vs,
                Real* __restrict dx, Real* __restrict dv) {
  for (long i = begin; i < end; ++i) {
    dx[i] += vs[i];
    dv[i] += a[i];
    x[i] += sixth * dx[i];
    v[i] += sixth * dv[i];
  }
}

}  // namespace

StepResult RungeKutta4::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Eigen::Index n = s.x.size();
  for (VecX* w : {&a_, &x_stage_, &v_stage_, &dx_, &dv_}) ensure_size(*w, n);
  const Real half = 0.5 * h, sixth = h / 6;
  // One threaded pass per update, split as the force loop splits the particles.
  const auto pass = [&](auto&& update, Real c) {
    parallel::for_ranges(
        dynamics.threads(), n,
        [&](long begin, long end) {
          update(begin, end, c, s.x.data(), s.v.data(), a_.data(), x_stage_.data(), v_stage_.data(),
                 dx_.data(), dv_.data());
        },
        parallel::kMinItemsPerThread, 3);
  };
  // Each stage's dx/dt is its velocity after its own evaluation, which a seed_framework terrain
  // may reflect (stage 1: the step's own velocity, as in the course framework).
  dynamics.stage_acceleration(s.t, s.x, s.v, a_);
  pass(first_stage, half);
  dynamics.stage_acceleration(s.t + half, x_stage_, v_stage_, a_);
  pass(next_stage, half);
  dynamics.stage_acceleration(s.t + half, x_stage_, v_stage_, a_);
  pass(next_stage, h);
  dynamics.stage_acceleration(s.t + h, x_stage_, v_stage_, a_);
  pass(last_stage, sixth);
  s.t += h;
  return StepResult::success();
}

}  // namespace jelly
