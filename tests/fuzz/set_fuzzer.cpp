// Fuzz target: --set assignments. Lines of the input are assignments applied to the seed slope
// scene; each is accepted or an InputError, never a crash. The text version (apply_override)
// returns JSON that parses again.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/scene.hpp>

#include "fuzz/fuzz_target.hpp"

namespace {

const char* const kSeedSlope = R"({
  "description": "the seed report's slope",
  "cube": {"n": 3, "edge_length": 4, "origin": [-2.2222, 6.7778, -2.2222], "particle_mass": 1},
  "springs": {"structural": {"ks": 1400, "kd": 50}, "shear": {"ks": 1400, "kd": 50},
              "bending": {"ks": 1400, "kd": 50}},
  "gravity": [0, -9.8, 0],
  "terrains": [{"kind": "slope", "angle_degrees": 20, "contact": {"model": "seed"}},
               {"kind": "elevator", "motion": "seed"}],
  "integrator": {"name": "rk4", "dt": 0.001},
  "duration": 5
})";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly;
  std::vector<std::string> assignments;
  std::istringstream lines(std::string(reinterpret_cast<const char*>(data), size));
  for (std::string line; std::getline(lines, line) && assignments.size() < 8;) {
    assignments.push_back(line);
  }
  try {
    const Scene scene = parse_scene(kSeedSlope, assignments, "seed_slope.json");
    (void)scene_to_json(scene);
  } catch (const InputError&) {
  }
  if (!assignments.empty()) {
    std::string edited;
    try {
      edited = apply_override(kSeedSlope, assignments.front());
    } catch (const InputError&) {
      return 0;
    }
    // What the text version returns is JSON that reads back.
    try {
      (void)apply_override(edited, "description=\"again\"");
    } catch (const InputError& e) {
      fuzz::fail("apply_override wrote text it cannot read back: " + std::string(e.what()));
    }
  }
  return 0;
}
