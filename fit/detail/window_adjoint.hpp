#pragma once
// Internal: the exact-gradient path of fit_recording (docs/fitting.md). One shooting window of a
// recording replayed with implicit_euler and differentiated by its discrete adjoint
// (solvers/adjoint/detail/implicit_euler_adjoint.hpp): one forward and one backward pass give the
// gradient of any loss on the window's frames.
#include <functional>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/fit/spring_fit.hpp>
#include <jelly/solvers/adjoint/detail/implicit_euler_adjoint.hpp>

namespace jelly {

// A loss term on the replayed positions at recording frame `frame` (first < frame <= last):
// returns its value and writes dL/dx into `dl_dx` (3N, zero on entry).
using WindowFrameLoss = std::function<Real(int frame, const VecX& x, VecX& dl_dx)>;

// Replays frames [first, last] of `trajectory` from `start` with `model`'s coefficients (the
// trajectory's integrator, which must be implicit_euler, and terrains) and returns the summed
// loss of the frames after `first` with its gradient (coefficients per body and spring type,
// start state, ...). Throws InputError for what the adjoint does not differentiate and
// std::runtime_error when a step or a backward solve fails.
GradientResult fit_window_gradient(const Trajectory& trajectory, const Model& model, int first,
                                   int last, const State& start, const WindowFrameLoss& loss);

}  // namespace jelly
