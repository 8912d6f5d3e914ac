// Trajectory: validation with clear messages, restart states, and the replay cost.
#include <jelly/fit/spring_fit.hpp>

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>

#include "fit/fit_scenes.hpp"

namespace jelly {
namespace {

const std::array<SpringCoefficients, kSpringTypeCount> kCoefficients{
    SpringCoefficients{1000, 20}, SpringCoefficients{1000, 20}, SpringCoefficients{1000, 20}};

std::string error_of(const Trajectory& trajectory) {
  try {
    trajectory.validate();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Trajectory, SimulatedRecordingIsValid) {
  const Trajectory recording = testing::free_recording(testing::fit_cube(kCoefficients));
  EXPECT_EQ(recording.frames(), 51);
  EXPECT_TRUE(recording.has_velocities());
  EXPECT_NEAR(recording.times.back(), 0.5, 1e-9);
  EXPECT_EQ(error_of(recording), "");
}

TEST(Trajectory, TooFewFrames) {
  Trajectory recording = testing::free_recording(testing::fit_cube(kCoefficients));
  recording.times.resize(1);
  recording.positions.resize(1);
  recording.velocities.resize(1);
  EXPECT_EQ(error_of(recording),
            "recording.frames = 1 is invalid: at least 3 frames (a start state and two frames "
            "to compare)");
  // fit_recording checks the same.
  EXPECT_THROW(fit_recording(recording), InputError);
}

TEST(Trajectory, NoMotion) {
  const Model model = testing::fit_cube(kCoefficients);
  Trajectory recording;
  recording.model = model;
  for (int k = 0; k < 10; ++k) {
    recording.times.push_back(0.01 * k);
    recording.positions.push_back(model.rest_position);
  }
  const std::string message = error_of(recording);
  EXPECT_NE(message.find("recording.positions = no motion"), std::string::npos) << message;
  EXPECT_THROW(fit_recording(recording), InputError);
}

TEST(Trajectory, RigidMotionHasNothingToIdentify) {
  // Free fall from rest: the cube translates without deforming.
  const Model model = testing::fit_cube(kCoefficients);
  const Trajectory recording =
      simulate_trajectory(model, rest_state(model), {}, "rk4", 1e-3, 0.01, 0.1);
  const std::string message = error_of(recording);
  EXPECT_NE(message.find("rigid motion"), std::string::npos) << message;
}

TEST(Trajectory, SizesAndTimes) {
  const Trajectory good = testing::free_recording(testing::fit_cube(kCoefficients));
  Trajectory t = good;
  t.positions[3].resize(6);
  EXPECT_NE(error_of(t).find("recording.positions[3].size = 6"), std::string::npos);
  t = good;
  t.velocities.pop_back();
  EXPECT_NE(error_of(t).find("recording.velocities.size = 50"), std::string::npos);
  t = good;
  t.times[2] = t.times[1];
  EXPECT_NE(error_of(t).find("recording.times[2] - times[1] = 0"), std::string::npos);
  t = good;
  t.times[2] += 0.0005;
  EXPECT_NE(error_of(t).find("a whole number of steps"), std::string::npos) << error_of(t);
  t = good;
  t.positions[4][0] = std::nan("");
  EXPECT_NE(error_of(t).find("recording.positions[4]"), std::string::npos);
}

// Without recorded velocities, restarts use second-order finite differences of the positions.
TEST(Trajectory, FiniteDifferenceVelocities) {
  Trajectory recording = testing::free_recording(testing::fit_cube(kCoefficients));
  // A parabola x(t) = a + b t + c t^2 is differentiated exactly, also at both ends.
  Trajectory parabola = recording;
  parabola.velocities.clear();
  const VecX a = recording.positions[0], b = VecX::LinSpaced(a.size(), -1, 1),
             c = VecX::LinSpaced(a.size(), 2, -3);
  for (int k = 0; k < parabola.frames(); ++k) {
    const Real t = parabola.times[k];
    parabola.positions[k] = a + t * b + t * t * c;
  }
  for (int k : {0, 7, parabola.frames() - 1}) {
    const Real t = parabola.times[k];
    const State s = parabola.state(k);
    EXPECT_EQ(s.t, t);
    EXPECT_LT((s.v - (b + 2 * t * c)).lpNorm<Eigen::Infinity>(), 1e-9) << "frame " << k;
  }
  // Recorded velocities are used as they are.
  EXPECT_EQ(recording.state(5).v, recording.velocities[5]);
}

// Replaying with the recording's own coefficients reproduces it exactly (same integrator, dt
// and terrains; the coulomb contact keeps no state between steps), with or without windows.
TEST(Trajectory, ReplayWithTrueCoefficientsIsExact) {
  const Trajectory slope =
      testing::slope_recording(testing::fit_cube(kCoefficients, testing::kSlopeOrigin));
  EXPECT_EQ(replay_cost(slope, 0.1), 0);
  EXPECT_EQ(replay_cost(slope, 0), 0);
  Trajectory other = slope;
  other.model.springs.set_coefficients(SpringType::kShear, {1100, 20});
  EXPECT_GT(replay_cost(other, 0.1), 1e-6);
}

}  // namespace
}  // namespace jelly
