// What a run takes, checked before it starts: no step, absurd step or frame counts, steps lost to
// rounding, cubes beyond memory and recordings beyond the disk are InputErrors naming the field.
#include <jelly/io/detail/run_limits.hpp>

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/io/detail/memory_estimate.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

Scene seed_scene() {
  return parse_scene(R"({"terrains": [{"kind": "slope"}], "integrator": {"name": "rk4"},
                         "duration": 5})");
}

// The message of check_run_limits, or "" when the run is within them.
std::string limit_error(const Scene& scene, Real t_start = 0, RunLimits limits = {},
                        const std::string& output = "", const std::string& restart = "") {
  if (limits.memory_bytes < 0) limits.memory_bytes = 1e12;  // independent of the machine
  try {
    check_run_limits(scene, t_start, limits, output, restart);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MemoryEstimate, CubeCountsAreThoseOfTheBuilder) {
  for (int n = 2; n <= 7; ++n) {
    CubeSpec spec;
    spec.n = n;
    const Model m = build_cube(spec);
    EXPECT_EQ(cube_particle_count(n), m.num_particles()) << n;
    EXPECT_EQ(cube_spring_count(n), m.springs.size()) << n;
  }
  EXPECT_EQ(cube_spring_count(10), 12876);
  EXPECT_EQ(cube_spring_count(400), 1018727196);  // fits an int, as Springs::size() needs
  // Counts that would overflow, or of a negative edge, are refused naming n (issue 44).
  EXPECT_THROW(cube_spring_count(2000000), InputError);
  EXPECT_THROW(cube_particle_count(-5), InputError);
  EXPECT_THAT([] { cube_particle_count(-5); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("n = -5 is invalid")));
  EXPECT_GT(cube_spring_count(500000), 0);
}

// Python's run_until applies jelly run's limits to a simulator's run (issue 44).
TEST(RunLimits, RunUntilRefusesAbsurdRunsNamingTheField) {
  CubeSpec spec;
  spec.n = 2;
  const Model model = build_cube(spec);
  Simulator sim(model, rest_state(model), make_integrator("rk4"));
  EXPECT_NO_THROW(check_run_until(sim, 1.0));
  EXPECT_NO_THROW(check_run_until(sim, -1.0));  // no step
  EXPECT_THAT(
      [&] { check_run_until(sim, 1e9); },
      ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("t_end = 1e+09 is invalid")));
  EXPECT_THROW(check_run_until(sim, std::nan("")), InputError);
  State far = sim.state();
  far.t = -1e12;
  sim.set_state(far);
  EXPECT_THAT([&] { check_run_until(sim, 1.0); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("state.t = -1e+12")));
}

TEST(MemoryEstimate, GrowsWithTheCubeAndTheImplicitSolver) {
  const auto bytes = [](int n, const std::string& integrator, bool recording) {
    return estimate_memory_bytes(cube_particle_count(n), cube_spring_count(n), integrator,
                                 recording);
  };
  // The measured peaks of `jelly run` at n = 40 (scripts/memory_figures.py; docs/scenes.md,
  // "How close the memory estimate is"), each estimate within 2x of its peak.
  const auto within_2x = [](double estimate, double measured) {
    return estimate > measured / 2 && estimate < measured * 2;
  };
  EXPECT_TRUE(within_2x(bytes(40, "rk4", false), 109e6));
  EXPECT_TRUE(within_2x(bytes(40, "implicit_euler", false), 139e6));
  EXPECT_TRUE(within_2x(bytes(40, "projective_dynamics", false), 876e6));
  EXPECT_GT(bytes(10, "rk4", true), bytes(10, "rk4", false));
  EXPECT_GT(bytes(400, "rk4", false), 80e9);  // the docs' largest cube
  EXPECT_EQ(bytes_text(86.2e9), "86.2 GB");
  EXPECT_EQ(bytes_text(512), "512 bytes");
}

TEST(RunLimits, TheSeedSceneIsWithinThem) {
  const RunEstimate e = estimate_run(seed_scene(), 0, true);
  EXPECT_EQ(e.steps, 5000);
  EXPECT_EQ(e.frames, 301);  // 1 + 5 s at 60 frames/s
  EXPECT_GT(e.recording_bytes, 301 * 48000.0);
  EXPECT_EQ(limit_error(seed_scene(), 0, {}, "out.h5"), "");
}

TEST(RunLimits, ATimeStepLongerThanTheRunTakesNoStep) {
  Scene s = seed_scene();
  s.integrator.dt = 10;
  EXPECT_EQ(limit_error(s),
            "integrator.dt = 10 is invalid: larger than twice the duration (5 s): the run would "
            "take no step");
  s.integrator.dt = 6;  // (5 / 6 rounds to one step: the loop runs while t < 5 - 3)
  EXPECT_EQ(limit_error(s), "");
}

TEST(RunLimits, ARestartAtOrAfterTheDurationTakesNoStep) {
  EXPECT_EQ(limit_error(seed_scene(), 5, {}, "", "run.h5"),
            "duration = 5 is invalid: the run would take no step: it starts at t = 5 s (the "
            "checkpoint of run.h5), and a duration is the time the run ends at: more than "
            "5.0005 s");
}

TEST(RunLimits, AbsurdStepCountsAndStepsLostToRoundingAreRefused) {
  Scene s = seed_scene();
  s.integrator.dt = 1e-9;
  EXPECT_EQ(limit_error(s),
            "integrator.dt = 1e-09 is invalid: a step giving at most 1000000000 steps: "
            "5000000000 steps from t = 0 s to the duration, 5 s");
  s.integrator.dt = 1e-3;
  s.duration = 1e300;
  EXPECT_THAT(limit_error(s), StartsWith("integrator.dt = 0.001 is invalid: a step that is not "
                                         "lost to rounding at t = 1e+300 s"));
  // A checkpoint far in the past: t + dt == t.
  EXPECT_THAT(limit_error(seed_scene(), -1e300, {}, "", "run.h5"),
              StartsWith("integrator.dt = 0.001 is invalid: a step that is not lost to rounding"));
  EXPECT_THAT(limit_error(seed_scene(), std::nan(""), {}, "", "run.h5"),
              StartsWith("start time (the checkpoint of run.h5) = nan is invalid"));
}

TEST(RunLimits, OutputIntervalsAreBounded) {
  Scene s = seed_scene();
  s.output_interval = 1e-300;  // the next output time would never move
  EXPECT_THAT(limit_error(s), StartsWith("output_interval = 1e-300 is invalid: an interval that "
                                         "is not lost to rounding"));
  s.output_interval = 1e-9;  // 5e9 moves of the next output time
  EXPECT_EQ(limit_error(s),
            "output_interval = 1e-09 is invalid: at most 1000000000 intervals in the run (0 = "
            "every step)");
  s.output_interval = 0;  // every step: 5001 frames, fine; a recording of 1e8 steps is not
  EXPECT_EQ(limit_error(s, 0, {}, "out.h5"), "");
  s.duration = 1e5;
  EXPECT_EQ(limit_error(s, 0, {}, "out.h5"),
            "output_interval = 0 is invalid: an interval giving at most 10000000 recorded "
            "frames, not 100000001 (0 = every step)");
}

TEST(RunLimits, ACubeBeyondMemoryIsRefusedWithTheEstimate) {
  Scene s = seed_scene();
  CubeSpec cube = s.cube();
  cube.n = 400;
  s.set_cube(cube);
  RunLimits limits;
  limits.memory_bytes = 16e9;
  EXPECT_EQ(limit_error(s, 0, limits),
            "cube.n = 400 is invalid: a cube that fits in memory: the run needs about 100.7 GB "
            "(64000000 particles, 1018727196 springs, rk4), more than the 16.0 GB available");
}

TEST(RunLimits, ARecordingBeyondTheFreeDiskIsRefused) {
  RunLimits limits;
  limits.disk_bytes = 1e6;
  EXPECT_EQ(limit_error(seed_scene(), 0, limits, "out.h5"),
            "-o out.h5: the recording needs about 15.0 MB (301 frames, about 9.0 MB compressed), "
            "more than the 1.0 MB free on its file system");
  EXPECT_EQ(limit_error(seed_scene(), 0, limits), "");  // no recording
  EXPECT_GT(free_disk_bytes(::testing::TempDir() + "x.h5"), 0);
}

}  // namespace
}  // namespace jelly
