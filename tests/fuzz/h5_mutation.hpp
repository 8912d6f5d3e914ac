#pragma once
// For the recording and checkpoint fuzz targets: small valid recordings written once per process,
// and a copy of one altered by a program of HDF5 edits read from the fuzzer's input (datasets
// replaced by others of any shape, type and values, resized, deleted or swapped; attributes set
// to scalars, arrays or text; the stored scene edited). The readers must turn whatever results
// into an InputError or a valid object, never read out of bounds or hang.
#include <string>

#include <jelly/io/scene.hpp>

#include "fuzz/fuzz_input.hpp"

namespace jelly::fuzz {

// The pristine recordings: 0 = rk4 with seed contact on the slope, 1 = implicit_euler with
// coulomb contact inside its solve (a checkpoint with integrator state), 2 = implicit_euler with
// two cubes in contact (its state holds contact pairs between bodies).
constexpr int kPristineCount = 3;
const Scene& pristine_scene(int which);
// Makes the pristine recordings (simulations of 0.2 s, seconds under the sanitizers on a loaded
// machine). The HDF5 targets call it from LLVMFuzzerInitialize, so that the time is not charged
// to the first input: it ran into libFuzzer's -timeout=20 in a 10-minute run (docs/fuzzing.md).
void prepare_pristine();

struct Mutated {
  std::string path;  // a scratch copy, rewritten by the next call
  int which = 0;     // the pristine recording it started from
};

// Picks a pristine recording, copies it and applies the edits read from `in`. With
// `checkpoint_focus` the edits touch /checkpoint and /parameters only.
Mutated mutated_recording(FuzzInput& in, bool checkpoint_focus);

}  // namespace jelly::fuzz
