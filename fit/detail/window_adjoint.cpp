#include <jelly/fit/detail/window_adjoint.hpp>

#include <cmath>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/fit/detail/implicit_euler_ceres.hpp>
#include <jelly/fit/detail/window_start.hpp>
#include <jelly/solvers/adjoint/detail/projective_dynamics_adjoint.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

GradientResult fit_window_gradient(const Trajectory& trajectory, const Model& model, int first,
                                   int last, const State& start, const WindowFrameLoss& loss) {
  require(has_adjoint(trajectory.integrator), "recording integrator", trajectory.integrator,
          "implicit_euler or projective_dynamics for exact gradients");
  // One thread: the fit's windows are its unit of parallel work, and results must not depend on
  // the thread count. The recording's carried contact state at frame `first`, when it holds
  // one (the adjoint holds it: the first step's friction viscosities are constants of the
  // window).
  Simulator sim = window_simulator(trajectory, model, first, start, 1);
  // The step after which each compared frame is reached; frame_at[step] = recording frame or -1.
  GradientProblem problem;
  std::vector<int> frame_at;
  int steps = 0;
  frame_at.push_back(-1);
  for (int k = first + 1; k <= last; ++k) {
    const long n = std::lround((trajectory.times[k] - trajectory.times[k - 1]) / trajectory.dt);
    for (long i = 0; i < n; ++i) frame_at.push_back(-1);
    steps += static_cast<int>(n);
    frame_at[steps] = k;
    problem.loss_frames.push_back(steps);
  }
  problem.steps = steps;
  problem.loss = [&](int step, const State& state, VecX& dl_dx, VecX&) {
    return loss(frame_at[step], state.x, dl_dx);
  };
  return integrator_gradient(sim, problem);
}

}  // namespace jelly
