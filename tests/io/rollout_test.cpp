// Batched rollouts: the frame times a rollout plans are those a Simulator emits, each run equals
// its scene run alone bit for bit for any thread count, a diverged run stops alone, and runs of
// other particle counts or bad overrides are refused by name.
#include <jelly/io/detail/rollout.hpp>

#include <atomic>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/simulator.hpp>

#include "scene_files.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;

// Positions and times of every frame a Simulator of `scene` emits until `duration`.
class Frames final : public Observer {
 public:
  void on_frame(const Simulator& sim) override {
    x.insert(x.end(), sim.state().x.data(), sim.state().x.data() + sim.state().x.size());
    t.push_back(sim.state().t);
  }
  std::vector<Real> x, t;
};

Frames alone(Scene scene, Real duration, Real every) {
  scene.duration = duration;
  scene.output_interval = every;
  Simulator sim = make_simulator(scene);
  Frames frames;
  sim.add_observer(frames);
  sim.run_until(duration);
  return frames;
}

bool same_bits(const Real* a, const Real* b, std::size_t count) {
  return std::memcmp(a, b, count * sizeof(Real)) == 0;
}

const std::vector<std::vector<std::string>> kRuns = {
    {},
    {"bodies[0].springs.structural.ks=700"},
    {"bodies[0].velocity=[1.5, 2, -0.5]"},
    {"gravity=[0, -3, 1]", "integrator.dt=0.0005"},
    {"integrator.name=implicit_euler", "integrator.dt=0.002"},
};

// The seed slope with a 4 x 4 x 4 cube, as full JSON (its body is bodies[0]).
std::string small_slope() {
  return scene_to_json(load_scene(testing::scene_path("seed_slope.json"), {"cube.n=4"}));
}

TEST(Rollout, PlannedFrameTimesAreTheSimulatorsFrames) {
  const Scene scene = load_scene(testing::scene_path("seed_slope.json"), {"cube.n=3"});
  for (const Real dt : {0.001, 0.003, 0.0007}) {
    for (const Real every : {0.0, 0.01, 1.0 / 60, 0.0035}) {
      Scene s = scene;
      s.integrator.dt = dt;
      const Frames frames = alone(s, 0.1, every);
      const std::vector<Real> planned = rollout_frame_times(dt, every, 0.1);
      ASSERT_EQ(planned.size(), frames.t.size()) << "dt " << dt << ", every " << every;
      EXPECT_TRUE(same_bits(planned.data(), frames.t.data(), planned.size()));
    }
  }
}

TEST(Rollout, EachRunEqualsItsSceneAloneForAnyThreadCount) {
  const std::string json = small_slope();
  const Real duration = 0.2, every = 0.01;
  for (const int threads : {1, 2, 3}) {
    RolloutOptions options;
    options.duration = duration;
    options.every = every;
    options.velocities = true;
    options.threads = threads;
    const RolloutResult r = rollout(json, kRuns, options);
    ASSERT_EQ(r.runs, static_cast<long>(kRuns.size()));
    ASSERT_EQ(r.particles, 64);
    ASSERT_EQ(r.frames, 21);
    const std::size_t per_run = static_cast<std::size_t>(r.frames * r.particles * 3);
    for (long k = 0; k < r.runs; ++k) {
      EXPECT_EQ(r.run[k].status, "completed") << r.run[k].reason;
      const Frames f = alone(parse_scene(json, kRuns[k]), duration, every);
      ASSERT_EQ(f.t.size(), static_cast<std::size_t>(r.frames));
      EXPECT_TRUE(same_bits(r.positions.data() + k * per_run, f.x.data(), per_run))
          << "run " << k << ", " << threads << " threads";
      EXPECT_TRUE(same_bits(r.times.data() + k * r.frames, f.t.data(), f.t.size()));
    }
  }
}

TEST(Rollout, ADivergedRunStopsAlone) {
  RolloutOptions options;
  options.duration = 0.4;
  options.every = 0.01;
  const RolloutResult r = rollout(small_slope(),
                                  {{},
                                   {"integrator.name=explicit_euler", "integrator.dt=0.02",
                                    "bodies[0].springs.structural.ks=1e6"}},
                                  options);
  EXPECT_EQ(r.run[0].status, "completed");
  EXPECT_EQ(r.run[1].status, "diverged");
  EXPECT_FALSE(r.run[1].reason.empty());
  EXPECT_EQ(r.run[0].frames, r.frames);
  ASSERT_LT(r.run[1].frames, r.frames);
  const std::size_t per_run = static_cast<std::size_t>(r.frames * r.particles * 3);
  const Real* diverged = r.positions.data() + per_run;
  EXPECT_TRUE(std::isnan(diverged[r.run[1].frames * r.particles * 3]));
  EXPECT_TRUE(std::isnan(diverged[per_run - 1]));
  for (std::size_t i = 0; i < per_run; ++i) ASSERT_TRUE(std::isfinite(r.positions[i]));
}

TEST(Rollout, AStopFlagStopsEveryRun) {
  const std::atomic<bool> stop{true};
  RolloutOptions options;
  options.duration = 0.1;
  options.stop = &stop;
  const RolloutResult r = rollout(small_slope(), {{}, {}, {}}, options);
  for (const RolloutRun& run : r.run) {
    EXPECT_EQ(run.status, "stopped");
    EXPECT_EQ(run.frames, 0);
    EXPECT_FALSE(run.ok());
  }
  EXPECT_TRUE(std::isnan(r.positions.front()) && std::isnan(r.positions.back()));
}

TEST(Rollout, RefusesOtherParticleCountsAndBadOverridesByName) {
  RolloutOptions options;
  options.duration = 0.05;
  const std::string json = small_slope();
  try {
    rollout(json, {{}, {}, {"bodies[0].n=5"}}, options);
    FAIL() << "runs of 64 and 125 particles";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("overrides_per_run[2]"));
    EXPECT_THAT(e.what(), HasSubstr("125 particles"));
    EXPECT_THAT(e.what(), HasSubstr("64"));
  }
  try {
    rollout(json, {{}, {"bodies[0].springs.shear.ks=-1"}}, options);
    FAIL() << "a negative ks";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("overrides_per_run[1]"));
    EXPECT_THAT(e.what(), HasSubstr("bodies[0].springs.shear.ks"));
  }
  EXPECT_THROW(rollout(json, {{"duration=3"}}, options), InputError);
  EXPECT_THROW(rollout(json, {}, options), InputError);
  options.duration = -1;
  EXPECT_THROW(rollout(json, {{}}, options), InputError);
}

}  // namespace
}  // namespace jelly
