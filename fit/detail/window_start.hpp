#pragma once
// Internal: the simulator that replays a window of a recording (docs/fitting.md), started from a
// recorded frame with what the recording's own run carried into that frame when the recording
// holds it: implicit_euler's contact pairs between bodies (their stick or slide mode and friction
// viscosity) and its terrains' contact set, which a simulator started afresh does not have.
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/fit/spring_fit.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

// The integrator state a replay from recording frame `first` starts with: for implicit_euler past
// frame 0 the recording's own at that frame when the trajectory holds it (Trajectory::
// integrator_states); else empty (start afresh, as at frame 0, where the recording itself
// started without one). Rebuilding it by replaying the interval before frame `first` from frame
// first - 1 was tried: it brought the replays at the truth closer to the recording in one scene
// and further from it in others (docs/fitting.md), so a recording without the states starts
// its windows afresh.
std::vector<Real> window_start_state(const Trajectory& trajectory, int first);

// A simulator of `model` (the trajectory's integrator, terrains and body contact, dt) at `start`,
// the state of recording frame `first`, on `threads` threads, with window_start_state's state.
Simulator window_simulator(const Trajectory& trajectory, const Model& model, int first,
                           const State& start, int threads = 0);

}  // namespace jelly
