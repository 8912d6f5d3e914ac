// The contact statistics of a run (body contact pairs, broad- and narrow-phase time) are in the
// recording's /parameters attributes, equal to the run summary's.
#include <gtest/gtest.h>

#include <string>

#include <jelly/core/detail/json.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

// Two small cubes, one dropped onto the other resting on the floor: they touch from about 0.2 s.
Scene two_cubes() {
  return parse_scene(R"({
    "bodies": [
      {"kind": "cube", "name": "lower", "n": 3, "edge_length": 0.5, "origin": [0, 0.001, 0]},
      {"kind": "cube", "name": "upper", "n": 3, "edge_length": 0.5, "origin": [0.1, 0.8, 0.05]}
    ],
    "terrains": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                  "contact": {"model": "coulomb"}}],
    "integrator": {"name": "symplectic_euler", "dt": 0.001},
    "duration": 0.6, "output_interval": 0.05})");
}

TEST(ContactStatistics, InTheRecordingsAttributes) {
  TempDir dir;
  const std::string path = dir.file("stats.h5");
  const Scene scene = two_cubes();
  RunReport report;
  {
    Simulator sim = make_simulator(scene);
    RecorderOptions options;
    options.scene_json = scene_to_json(scene);
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    report = sim.run_until(scene.duration);
    ASSERT_TRUE(report.ok()) << report.reason;
  }
  const Recording r = read_recording(path);
  for (const char* name : {"body_contact_pairs", "broad_phase_ms", "narrow_phase_ms"}) {
    const std::string key = std::string("statistics.") + name;
    ASSERT_EQ(r.attributes.count(key), 1u) << key;
    const Real stored = std::stod(r.attributes.at(key));
    EXPECT_NEAR(stored, report.statistics.at(name), 1e-9 * std::abs(report.statistics.at(name)))
        << key;
  }
  // The cubes touched (pairs summed over the steps), and both phases ran at every step.
  EXPECT_GT(std::stod(r.attributes.at("statistics.body_contact_pairs")), 0);
  EXPECT_GT(std::stod(r.attributes.at("statistics.broad_phase_ms")), 0);
  EXPECT_GT(std::stod(r.attributes.at("statistics.narrow_phase_ms")), 0);
}

}  // namespace
}  // namespace jelly
