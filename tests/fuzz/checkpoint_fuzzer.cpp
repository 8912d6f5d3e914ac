// Fuzz target: restarts from checkpoints of files altered by the edits of h5_mutation.hpp
// (their /checkpoint and /parameters): read_checkpoint, check_same_scene, the run limits from the
// checkpoint's time, restore() into the recording's own simulator, and a few steps. Every
// outcome is an InputError or a run that stays bounded; none crashes.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include <jelly/core/errors.hpp>
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/detail/run_limits.hpp>

#include "fuzz/h5_mutation.hpp"

// libFuzzer calls it once before the first input (replay_main.cpp does too).
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  jelly::fuzz::prepare_pristine();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly;
  fuzz::FuzzInput in(data, size);
  const fuzz::Mutated m = fuzz::mutated_recording(in, /*checkpoint_focus=*/true);
  Checkpoint cp;
  try {
    cp = read_checkpoint(m.path);
  } catch (const InputError&) {
    return 0;
  }
  Scene scene = fuzz::pristine_scene(m.which);
  scene.duration = 1;
  try {
    check_same_scene(cp, scene, m.path);
  } catch (const InputError&) {
  }
  try {
    RunLimits limits;
    limits.memory_bytes = 1e9;
    check_run_limits(scene, cp.state.t, limits, "", m.path);
  } catch (const InputError&) {
  }
  // The library's restore, as a program that skips the checks above would call it.
  try {
    Simulator sim = make_simulator(scene);
    restore(sim, cp);
    for (int i = 0; i < 3; ++i) {
      if (!sim.step().ok) break;
    }
    (void)sim.run_until(sim.state().t + 2 * scene.integrator.dt);
  } catch (const InputError&) {
  }
  return 0;
}
