#pragma once
// Internal: the simulator that replays a window of a recording (docs/fitting.md), started from a
// recorded frame with what the recording's own run carried into that frame: implicit_euler's
// contact pairs between bodies (their stick or slide mode and friction viscosity) and its
// terrains' contact set, which a simulator started afresh would not have.
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/fit/trajectory.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

// The integrator state a replay of `model` from recording frame `first` starts with: for
// implicit_euler past frame 0 the recording's own at that frame when the trajectory holds it,
// else one rebuilt as the recording's run built it: the interval before frame `first` replayed
// from frame first - 1 with `model` (on `threads` threads), its integrator's internal state kept.
// Empty (start afresh) for other integrators, at frame 0 (the recording itself started without
// one) and when that replay fails.
std::vector<Real> window_start_state(const Trajectory& trajectory, const Model& model, int first,
                                     int threads = 0);

// A simulator of `model` (the trajectory's integrator, terrains and body contact, dt) at `start`,
// the state of recording frame `first`, on `threads` threads, with window_start_state's state
// (or `carried`, that state computed before for the same model and frame).
Simulator window_simulator(const Trajectory& trajectory, const Model& model, int first,
                           const State& start, int threads = 0,
                           const std::vector<Real>* carried = nullptr);

}  // namespace jelly
