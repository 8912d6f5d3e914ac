#include <jelly/solvers/run_report.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/simulator.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

State resting_cube(const Model& model) { return rest_state(model); }

bool contains(const std::optional<std::string>& why, const std::string& text) {
  return why && why->find(text) != std::string::npos;
}

TEST(DivergenceGuard, AFiniteStateWithinTheLimitsPasses) {
  const Model model = build_cube(testing::small_cube(3));
  const DivergenceGuard guard;
  EXPECT_EQ(guard.check(resting_cube(model)), std::nullopt);
  EXPECT_EQ(guard.check(model, resting_cube(model)), std::nullopt);
}

TEST(DivergenceGuard, NonFinitePositionsAndVelocities) {
  const Model model = build_cube(testing::small_cube(3));
  const DivergenceGuard guard;
  for (Real bad : {std::numeric_limits<Real>::quiet_NaN(), std::numeric_limits<Real>::infinity(),
                   -std::numeric_limits<Real>::infinity()}) {
    State s = resting_cube(model);
    s.x[3 * 5 + 1] = bad;
    EXPECT_TRUE(contains(guard.check(s), "particle 5 has a non-finite position or velocity"))
        << bad;
    s = resting_cube(model);
    s.v[3 * 7 + 2] = bad;
    EXPECT_TRUE(contains(guard.check(model, s), "particle 7 has a non-finite")) << bad;
  }
}

// On threads the scan names the same particle: the first one, wherever the threads' ranges split
// the particles (a cube of 4,096 particles: up to 4 threads scan it).
TEST(DivergenceGuard, ThreadsNameTheFirstParticle) {
  const Model model = build_cube(testing::small_cube(16));
  ASSERT_EQ(model.num_particles(), 4096);
  const DivergenceGuard guard;
  State s = resting_cube(model);
  for (int threads : {1, 2, 3, 4}) EXPECT_EQ(guard.check(s, threads), std::nullopt) << threads;
  particle(s.v, 3500) = Vec3(0, 600, 0);  // in the last thread's range
  for (int threads : {1, 2, 3, 4}) {
    EXPECT_TRUE(contains(guard.check(s, threads), "particle 3500 moves at")) << threads;
  }
  s.x[3 * 1500] = std::numeric_limits<Real>::quiet_NaN();  // and one before it
  for (int threads : {1, 2, 3, 4}) {
    EXPECT_TRUE(contains(guard.check(model, s, threads), "particle 1500 has a non-finite"))
        << threads;
  }
}

// The limits are strict: exactly at the limit passes, beyond it is divergence, and the reason
// names the particle, the value and the limit.
TEST(DivergenceGuard, RunawaySpeed) {
  const Model model = build_cube(testing::small_cube(3));
  DivergenceGuard guard;
  guard.max_speed = 10;
  State s = resting_cube(model);
  particle(s.v, 4) = Vec3(6, 8, 0);  // |v| = 10
  EXPECT_EQ(guard.check(s), std::nullopt);
  particle(s.v, 4) = Vec3(6, 8, 0.1);
  const auto why = guard.check(s);
  EXPECT_TRUE(contains(why, "particle 4 moves at")) << why.value_or("");
  EXPECT_TRUE(contains(why, "above the limit of 10 m/s")) << why.value_or("");
}

TEST(DivergenceGuard, Distance) {
  const Model model = build_cube(testing::small_cube(3));
  DivergenceGuard guard;
  guard.max_distance = 100;
  State s = resting_cube(model);
  particle(s.x, 2) = Vec3(0, -100, 0);
  EXPECT_EQ(guard.check(s), std::nullopt);
  particle(s.x, 2) = Vec3(0, -100.5, 0);
  const auto why = guard.check(s);
  EXPECT_TRUE(contains(why, "particle 2 is 100.5 m from the origin")) << why.value_or("");
  EXPECT_TRUE(contains(why, "beyond the limit of 100 m")) << why.value_or("");
}

// The energy cap is checked only with the model, and only when finite.
TEST(DivergenceGuard, EnergyCap) {
  const Model model = build_cube(testing::small_cube(3));
  State s = resting_cube(model);
  particle(s.v, 0) = Vec3(3, 0, 0);
  const Real e = total_energy(model, s);
  DivergenceGuard guard;
  EXPECT_EQ(guard.check(model, s), std::nullopt);  // infinite: not checked
  guard.max_energy = e + 1e-9;
  EXPECT_EQ(guard.check(model, s), std::nullopt);
  guard.max_energy = e - 1;
  EXPECT_TRUE(contains(guard.check(model, s), "total energy"));
  EXPECT_EQ(guard.check(s), std::nullopt);  // without the model: no energy
}

TEST(DivergenceGuard, InvalidLimitsNameTheField) {
  DivergenceGuard guard;
  EXPECT_NO_THROW(guard.validate());
  guard.max_speed = 0;
  EXPECT_THROW(guard.validate(), InputError);
  guard = {};
  guard.max_distance = -1;
  EXPECT_THROW(guard.validate(), InputError);
  guard = {};
  guard.max_energy = std::numeric_limits<Real>::quiet_NaN();
  try {
    guard.validate();
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("divergence.max_energy"), std::string::npos);
  }
}

// The Simulator stops at the first step that leaves the limits, with the reason and the time.
TEST(DivergenceGuard, StopsTheSimulator) {
  const Model model = build_cube(testing::small_cube(3));
  SimulatorOptions o;
  o.dt = 0.01;
  o.divergence.max_speed = 0.5;  // free fall reaches 0.5 m/s after ~0.051 s
  Simulator sim(model, rest_state(model), make_integrator("symplectic_euler"), o);
  const RunReport report = sim.run_until(1.0);
  EXPECT_EQ(report.status, RunStatus::kDiverged);
  EXPECT_EQ(report.steps, 6);  // v = 0.588 m/s after 6 steps of 9.8 x 0.01
  EXPECT_NEAR(report.t, 0.06, 1e-12);
  EXPECT_NE(report.reason.find("above the limit of 0.5 m/s"), std::string::npos) << report.reason;
}

}  // namespace
}  // namespace jelly
