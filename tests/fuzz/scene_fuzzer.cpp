// Fuzz target: scene files. Any text is either a scene or an InputError; a scene written back
// with scene_to_json reads back to the same text; the run limits of a scene are an InputError
// or fine; a small scene (27 particles at most) builds a simulator that takes a few steps without a
// crash.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/run_limits.hpp>
#include <jelly/io/scene.hpp>

#include "fuzz/fuzz_target.hpp"

namespace jelly::fuzz {

void run_scene(const Scene& scene) {
  RunLimits limits;
  limits.memory_bytes = 1e9;  // independent of the machine
  try {
    check_run_limits(scene, 0, limits);
  } catch (const InputError&) {
  }
  if (estimate_run(scene).particles > 27) return;  // keep each input fast
  try {
    Simulator sim = make_simulator(scene);
    for (int i = 0; i < 3; ++i) {
      if (!sim.step().ok) break;
    }
  } catch (const InputError&) {
  }
}

}  // namespace jelly::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scene scene;
  try {
    scene = parse_scene(text, {}, "fuzz.json");
  } catch (const InputError&) {
    return 0;
  }
  // Round trip: what scene_to_json writes, parse_scene reads back to the same scene.
  const std::string written = scene_to_json(scene);
  const std::string again = scene_to_json(parse_scene(written, {}, "written.json"));
  if (again != written) fuzz::fail("scene_to_json does not round-trip:\n" + written + "\n" + again);
  fuzz::run_scene(scene);
  return 0;
}
