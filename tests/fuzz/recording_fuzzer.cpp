// Fuzz target: reading recordings (read_recording, describe_recording, and the fit's
// trajectory_from_recording) of files altered by the edits of h5_mutation.hpp. Every outcome is
// a valid object or an InputError.
#include <cstddef>
#include <cstdint>

#include <jelly/core/errors.hpp>
#include <jelly/fit/detail/recording_trajectory.hpp>
#include <jelly/io/recording.hpp>

#include "fuzz/h5_mutation.hpp"

// libFuzzer calls it once before the first input (replay_main.cpp does too).
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  jelly::fuzz::prepare_pristine();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly;
  fuzz::FuzzInput in(data, size);
  const fuzz::Mutated m = fuzz::mutated_recording(in, /*checkpoint_focus=*/false);
  try {
    const Recording r = read_recording(m.path);
    try {
      (void)trajectory_from_recording(r);
    } catch (const InputError&) {
    }
  } catch (const InputError&) {
  }
  try {
    (void)describe_recording(m.path);
  } catch (const InputError&) {
  }
  return 0;
}
