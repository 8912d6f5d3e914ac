// fit_recording: coefficients recovered from in-memory recordings with known values.
#include <jelly/fit/spring_fit.hpp>

#include <cmath>
#include <iostream>
#include <tuple>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_spec.hpp>

#include "fit/fit_scenes.hpp"

namespace jelly {
namespace {

using testing::fit_cube;

constexpr std::array<SpringCoefficients, kSpringTypeCount> kEqual{
    SpringCoefficients{1000, 20}, SpringCoefficients{1000, 20}, SpringCoefficients{1000, 20}};
constexpr std::array<SpringCoefficients, kSpringTypeCount> kPerType{
    SpringCoefficients{1000, 20}, SpringCoefficients{1500, 30}, SpringCoefficients{800, 10}};
constexpr std::array<SpringCoefficients, kSpringTypeCount> kPerTypeKs{
    SpringCoefficients{1000, 20}, SpringCoefficients{1500, 20}, SpringCoefficients{800, 20}};

// The seed's coefficients as the starting guess: 40 % off in ks, 2.5 to 5 times in kd.
void reset_to_seed(Trajectory& trajectory) {
  for (int t = 0; t < kSpringTypeCount; ++t)
    trajectory.model.springs.set_coefficients(static_cast<SpringType>(t), {1400, 50});
}

Real true_value(const FittedParameter& p,
                const std::array<SpringCoefficients, kSpringTypeCount>& truth) {
  const int t = p.parameter.type ? static_cast<int>(*p.parameter.type) : 0;
  return p.parameter.quantity == FitParameter::Quantity::kKs ? truth[t].ks : truth[t].kd;
}

void expect_recovered(const FitResult& result,
                      const std::array<SpringCoefficients, kSpringTypeCount>& truth, Real relative,
                      Real sigmas = 0) {
  EXPECT_TRUE(result.converged) << result.report();
  for (const FittedParameter& p : result.parameters) {
    const Real expected = true_value(p, truth);
    EXPECT_NEAR(p.value, expected, relative * expected) << p.name << "\n" << result.report();
    if (sigmas > 0) {
      ASSERT_TRUE(result.covariance_ok) << result.report();
      EXPECT_GT(p.stddev, 0) << p.name;
      EXPECT_LT(std::abs(p.value - expected), sigmas * p.stddev) << p.name << "\n"
                                                                 << result.report();
    }
  }
  std::cout << result.report();
}

TEST(ParseFreeParameters, NamesAndErrors) {
  const auto all = parse_free_parameters("ks,kd");
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].name(), "ks");
  EXPECT_EQ(all[1].name(), "kd");
  const auto per_type = parse_free_parameters("ks.structural, ks.shear,ks.bending,kd");
  ASSERT_EQ(per_type.size(), 4u);
  EXPECT_EQ(per_type[1].name(), "ks.shear");
  EXPECT_TRUE(per_type[1].applies_to(SpringType::kShear));
  EXPECT_FALSE(per_type[1].applies_to(SpringType::kBending));
  EXPECT_TRUE(per_type[3].applies_to(SpringType::kBending));
  // Per body: a body's name before the coefficient's ("ks.ks": the body named "ks").
  const auto per_body = parse_free_parameters("soft.ks,stiff.ks.shear,ks.ks,kd");
  ASSERT_EQ(per_body.size(), 4u);
  EXPECT_EQ(per_body[0].body, "soft");
  EXPECT_EQ(per_body[0].name(), "soft.ks");
  EXPECT_EQ(per_body[1].name(), "stiff.ks.shear");
  EXPECT_TRUE(per_body[1].applies_to(SpringType::kShear));
  EXPECT_EQ(per_body[2].body, "ks");
  EXPECT_EQ(per_body[3].body, "");
  for (const char* bad : {"", "ks,", "k", "ks.diagonal", "ks,ks", "ks,ks.shear", "ksx", "kd.",
                          "soft.", "soft.kx", "soft.ks,ks", "soft.ks,soft.ks.shear", ".ks"}) {
    try {
      parse_free_parameters(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("free = ", 0), 0u) << e.what();
    }
  }
}

// Two cubes of different stiffness in one recording: one ks per body (and a shared kd) recovers
// each body's own; a body the recording lacks is an error naming those it has.
TEST(FitRecording, OneStiffnessPerBody) {
  Model model;
  for (const auto& [name, ks, x] : {std::tuple<const char*, Real, Real>{"soft", 800, -1.5},
                                    std::tuple<const char*, Real, Real>{"stiff", 2000, 1.5}}) {
    BodySpec body;
    body.name = name;
    CubeShape cube;
    cube.n = 3;
    cube.edge_length = 1;
    cube.origin = Vec3(x, 1, -0.5);
    body.shape = cube;
    body.material.springs.fill({ks, 20});
    add_body(model, body, "");
  }
  Trajectory recording = testing::free_recording(model);
  reset_to_seed(recording);
  FitOptions options;
  options.free = parse_free_parameters("soft.ks,stiff.ks,kd");
  const FitResult result = fit_recording(recording, options);
  EXPECT_TRUE(result.converged) << result.report();
  EXPECT_NEAR(result.at("soft.ks").value, 800, 8);
  EXPECT_NEAR(result.at("stiff.ks").value, 2000, 20);
  EXPECT_NEAR(result.at("kd").value, 20, 0.2);
  Material soft, stiff;
  apply_fit(soft, result, "soft");
  apply_fit(stiff, result, "stiff");
  EXPECT_EQ(soft.springs[1].ks, result.at("soft.ks").value);
  EXPECT_EQ(stiff.springs[1].ks, result.at("stiff.ks").value);
  EXPECT_EQ(stiff.springs[2].kd, result.at("kd").value);

  options.free = parse_free_parameters("blob.ks");
  try {
    fit_recording(recording, options);
    ADD_FAILURE() << "fitted a body the recording does not have";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "free = blob.ks is invalid: a body of the recording: one of soft, stiff");
  }
}

TEST(FitRecording, AllTypesTogetherFreeFlight) {
  Trajectory recording = testing::free_recording(fit_cube(kEqual));
  reset_to_seed(recording);
  expect_recovered(fit_recording(recording), kEqual, 0.01);
}

TEST(FitRecording, PerTypeFreeFlight) {
  Trajectory recording = testing::free_recording(fit_cube(kPerType));
  reset_to_seed(recording);
  FitOptions options;
  options.free =
      parse_free_parameters("ks.structural,ks.shear,ks.bending,kd.structural,kd.shear,kd.bending");
  expect_recovered(fit_recording(recording, options), kPerType, 0.01);
}

TEST(FitRecording, AllTypesTogetherOnSlope) {
  Trajectory recording = testing::slope_recording(fit_cube(kEqual, testing::kSlopeOrigin));
  reset_to_seed(recording);
  expect_recovered(fit_recording(recording), kEqual, 0.01);
}

TEST(FitRecording, PerTypeOnSlope) {
  Trajectory recording = testing::slope_recording(fit_cube(kPerType, testing::kSlopeOrigin));
  reset_to_seed(recording);
  FitOptions options;
  options.free =
      parse_free_parameters("ks.structural,ks.shear,ks.bending,kd.structural,kd.shear,kd.bending");
  expect_recovered(fit_recording(recording, options), kPerType, 0.01);
}

TEST(FitRecording, NoisyPositionsFreeFlight) {
  Trajectory recording = testing::free_recording(fit_cube(kPerTypeKs));
  testing::add_noise(recording, 1e-3);
  reset_to_seed(recording);
  FitOptions options;
  options.free = parse_free_parameters("ks.structural,ks.shear,ks.bending,kd");
  expect_recovered(fit_recording(recording, options), kPerTypeKs, 0.05, 3);
}

TEST(FitRecording, NoisyPositionsOnSlope) {
  Trajectory recording = testing::slope_recording(fit_cube(kEqual, testing::kSlopeOrigin));
  testing::add_noise(recording, 1e-3);
  reset_to_seed(recording);
  expect_recovered(fit_recording(recording), kEqual, 0.05, 3);
}

TEST(FitRecording, ApplyFitAndReport) {
  Trajectory recording = testing::free_recording(fit_cube(kPerType));
  reset_to_seed(recording);
  FitOptions options;
  options.free = parse_free_parameters("ks.structural,ks.shear,ks.bending,kd");
  options.initial = {{"kd", 25}};
  options.compute_covariance = false;
  const FitResult result = fit_recording(recording, options);
  EXPECT_EQ(result.at("kd").initial, 25);
  EXPECT_EQ(result.at("ks.shear").initial, 1400);
  EXPECT_THROW(result.at("kd.shear"), InputError);
  // One kd for all types cannot match 20 / 30 / 10 exactly, but lands in between.
  EXPECT_GT(result.at("kd").value, 10);
  EXPECT_LT(result.at("kd").value, 30);
  EXPECT_FALSE(result.covariance_ok);

  CubeSpec spec = testing::small_cube(3, 1, Vec3(-0.5, 1, -0.5));
  apply_fit(spec, result);
  EXPECT_EQ(spec.springs[1].ks, result.at("ks.shear").value);
  EXPECT_EQ(spec.springs[2].ks, result.at("ks.bending").value);
  for (const SpringCoefficients& c : spec.springs) EXPECT_EQ(c.kd, result.at("kd").value);
  // The spec and the model agree, and the fitted model replays better than the start.
  Model model = recording.model;
  apply_fit(model, result);
  const Model from_spec = build_cube(spec);
  EXPECT_EQ(model.springs.ks, from_spec.springs.ks);
  EXPECT_EQ(model.springs.kd, from_spec.springs.kd);
  Trajectory fitted = recording;
  fitted.model = model;
  EXPECT_NEAR(replay_cost(fitted, options.window), result.final_cost, 1e-12);
  EXPECT_LT(result.final_cost, 0.5 * result.initial_cost);

  const std::string report = result.report();
  for (const char* part : {"ks.structural = ", "kd = ", "iterations", "Ceres Solver Report",
                           "covariance: failed: not requested"})
    EXPECT_NE(report.find(part), std::string::npos) << part << "\n" << report;
}

// Windows are independent residual blocks: two threads evaluate them in parallel, each replay
// with its own simulator and terrains, and find the same coefficients.
TEST(FitRecording, TwoThreadsAgreeWithOne) {
  Trajectory recording = testing::slope_recording(fit_cube(kEqual, testing::kSlopeOrigin));
  reset_to_seed(recording);
  testing::add_noise(recording, 1e-3);
  FitOptions options;
  options.compute_covariance = false;
  const FitResult one = fit_recording(recording, options);
  options.num_threads = 2;
  const FitResult two = fit_recording(recording, options);
  for (const char* name : {"ks", "kd"})
    EXPECT_NEAR(two.at(name).value, one.at(name).value, 1e-8 * one.at(name).value) << name;
}

TEST(FitRecording, InvalidOptions) {
  const Trajectory recording = testing::free_recording(fit_cube(kEqual));
  auto message = [&](const FitOptions& options) -> std::string {
    try {
      fit_recording(recording, options);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  FitOptions options;
  options.initial = {{"ks.shear", 1000}};
  EXPECT_EQ(message(options).rfind("initial.ks.shear = 1000 is invalid", 0), 0u);
  options.initial = {{"ks", -1}};
  EXPECT_EQ(message(options).rfind("initial.ks = -1 is invalid", 0), 0u);
  options = {};
  options.window = -0.1;
  EXPECT_EQ(message(options).rfind("window = -0.10000000000000001 is invalid", 0), 0u);
  // A model without bending springs (n = 2) has no ks.bending to fit.
  Trajectory two = testing::free_recording(build_cube(testing::small_cube(2, 1)));
  options = {};
  options.free = parse_free_parameters("ks.bending");
  try {
    fit_recording(two, options);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "free = ks.bending is invalid: a spring type the model has");
  }
}

// Without recorded velocities the restarts use finite differences of the positions. Their error
// (frames 10 ms apart against oscillation periods of about 0.1 s) biases the fit: measured
// ks -9.7 % and kd -3.4 % on this noise-free recording, a bias the standard deviations do not
// cover (docs/fitting.md). The test bounds that bias; it is a known limitation, not a target.
TEST(FitRecording, WithoutVelocitiesFreeFlight) {
  Trajectory recording = testing::free_recording(fit_cube(kEqual), /*velocities=*/false);
  ASSERT_FALSE(recording.has_velocities());
  reset_to_seed(recording);
  expect_recovered(fit_recording(recording), kEqual, 0.12);
}

// Fitting each window's initial velocity (3N unknowns per window) instead of taking it from
// finite differences removes that bias. 0.3 s (3 windows, 245 unknowns) to keep the test short.
TEST(FitRecording, FittedRestartVelocitiesWithoutRecordedVelocities) {
  const Model model = fit_cube(kEqual);
  Trajectory recording =
      simulate_trajectory(model, testing::excited_state(model), {}, "rk4", testing::kFitDt,
                          testing::kFrameInterval, 0.3, /*record_velocities=*/false);
  reset_to_seed(recording);
  FitOptions options;
  options.fit_restart_velocities = true;
  options.compute_covariance = false;
  const FitResult result = fit_recording(recording, options);
  expect_recovered(result, kEqual, 0.01);
  ASSERT_EQ(result.restart_velocities.size(), 3u);
  // The fitted restart velocity of the second window is the simulated one (the recording's own
  // replay from the true state), not the finite difference.
  const Trajectory with_velocities =
      simulate_trajectory(model, testing::excited_state(model), {}, "rk4", testing::kFitDt,
                          testing::kFrameInterval, 0.3);
  const VecX& truth = with_velocities.velocities[10];
  EXPECT_LT((result.restart_velocities[1] - truth).lpNorm<Eigen::Infinity>(),
            1e-6 * truth.lpNorm<Eigen::Infinity>());
  // The finite difference is off by 0.4 % of the largest speed: enough for a 10 % bias in ks.
  EXPECT_GT((recording.state(10).v - truth).lpNorm<Eigen::Infinity>(),
            1e-3 * truth.lpNorm<Eigen::Infinity>());
}

}  // namespace
}  // namespace jelly
