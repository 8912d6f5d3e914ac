// fit_recording on exact gradients (the adjoint of implicit_euler): coefficients recovered from
// synthetic implicit_euler recordings, the path named in the report, the numeric path as the
// fallback for what the adjoint refuses, and both paths agreeing on a noisy recording.
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/fit/spring_fit.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

#include "fit/fit_scenes.hpp"

namespace jelly {
namespace {

using testing::fit_cube;

constexpr Real kAdjointFitDt = 0.005;  // implicit_euler's step of the recordings
constexpr std::array<SpringCoefficients, kSpringTypeCount> kTruth{
    SpringCoefficients{1000, 20}, SpringCoefficients{1000, 20}, SpringCoefficients{1000, 20}};

Trajectory implicit_recording(bool on_slope, bool velocities = true) {
  const Model model = on_slope ? fit_cube(kTruth, testing::kSlopeOrigin) : fit_cube(kTruth);
  Trajectory t = simulate_trajectory(
      model, testing::excited_state(model), on_slope ? testing::slope_terrain() : TerrainFactory{},
      "implicit_euler", kAdjointFitDt, testing::kFrameInterval, testing::kDuration, velocities);
  for (int type = 0; type < kSpringTypeCount; ++type)
    t.model.springs.set_coefficients(static_cast<SpringType>(type), {1400, 30});
  return t;
}

void expect_adjoint_recovery(const Trajectory& recording, Real relative) {
  FitOptions options;
  options.gradients = FitGradients::kAdjoint;
  options.compute_covariance = false;
  const FitResult result = fit_recording(recording, options);
  std::cout << result.report();
  EXPECT_EQ(result.gradient_path, "adjoint");
  EXPECT_NE(result.report().find("derivatives: adjoint (exact gradients"), std::string::npos)
      << result.report();
  EXPECT_TRUE(result.converged) << result.report();
  EXPECT_NEAR(result.at("ks").value, 1000, relative * 1000) << result.report();
  EXPECT_NEAR(result.at("kd").value, 20, relative * 20) << result.report();
  EXPECT_GT(result.adjoint_passes, 0);
  EXPECT_EQ(result.replays, 0);  // no replay without the adjoint (no covariance asked)
}

TEST(FitAdjoint, RecoversKsAndKdInFreeFlight) {
  expect_adjoint_recovery(implicit_recording(false), 1e-6);
}

// On the slope the replays restart without the recording run's contact state (its friction
// viscosities, set by the solve before), so the cost is not 0 at the truth and its minimum is
// slightly off it; the sliding contacts' viscosities are held by the adjoint. Both paths must
// find the same minimum, close to the truth.
TEST(FitAdjoint, AgreesWithTheNumericPathOnACoulombSlope) {
  const Trajectory recording = implicit_recording(true);
  FitOptions options;
  options.compute_covariance = false;
  options.gradients = FitGradients::kNumeric;
  const FitResult numeric = fit_recording(recording, options);
  options.gradients = FitGradients::kAdjoint;
  const FitResult exact = fit_recording(recording, options);
  std::cout << numeric.report() << exact.report();
  EXPECT_EQ(exact.gradient_path, "adjoint");
  EXPECT_TRUE(exact.converged) << exact.report();
  for (const char* name : {"ks", "kd"}) {
    const Real truth = std::string(name) == "ks" ? 1000 : 20;
    EXPECT_NEAR(exact.at(name).value, truth, 0.01 * truth) << name;
    EXPECT_NEAR(exact.at(name).value, numeric.at(name).value, 1e-3 * truth) << name;
  }
  EXPECT_LE(exact.final_cost, numeric.final_cost * (1 + 1e-3));
}

TEST(FitAdjoint, AutoFallsBackToNumericAndSaysWhy) {
  const Model model = fit_cube(kTruth);
  Trajectory recording = testing::free_recording(model);  // rk4
  FitOptions options;
  options.free = parse_free_parameters("ks");
  options.compute_covariance = false;
  const FitResult result = fit_recording(recording, options);
  EXPECT_EQ(result.gradient_path, "numeric");
  EXPECT_NE(result.report().find("derivatives: numeric (central differences of replays, "
                                 "Levenberg-Marquardt): the adjoint refused: the recording's "
                                 "integrator is rk4"),
            std::string::npos)
      << result.report();
  EXPECT_NEAR(result.at("ks").value, 1000, 1e-6 * 1000);

  options.gradients = FitGradients::kAdjoint;
  try {
    fit_recording(recording, options);
    ADD_FAILURE() << "the adjoint took an rk4 recording";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gradients = adjoint is invalid"), std::string::npos)
        << e.what();
  }
  // Terrain contact after the step: the adjoint refuses it at its first pass; auto takes the
  // numeric path.
  Trajectory after_step = implicit_recording(true);
  after_step.integrator_options.implicit.contact = ImplicitContactMode::kAfterStep;
  options.gradients = FitGradients::kAuto;
  options.max_iterations = 1;
  const FitResult fallback = fit_recording(after_step, options);
  EXPECT_EQ(fallback.gradient_path, "numeric") << fallback.report();
  EXPECT_NE(fallback.gradient_reason.find("the adjoint refused: terrains[0].contact.model"),
            std::string::npos)
      << fallback.report();
}

// Two cubes colliding in the air (frictionless contact between the bodies inside the solve, no
// restitution): the adjoint path fits through the contact. The windows restart without the
// recording's carried pairs, so the minimum is close to the truth, not on it.
TEST(FitAdjoint, RecoversKsAndKdThroughContactBetweenBodies) {
  Model model;
  for (int b = 0; b < 2; ++b) {
    BodySpec spec;
    spec.name = b == 0 ? "left" : "right";
    CubeShape shape;
    shape.n = 3;
    shape.edge_length = 0.5;
    shape.origin = Vec3(b == 0 ? -0.6 : 0.2, 1, 0);
    spec.shape = shape;
    spec.material.particle_mass = 0.1;
    spec.material.springs = kTruth;
    spec.velocity = Vec3(b == 0 ? 1.5 : 0, 0, 0);
    add_body(model, spec, "bodies[" + std::to_string(b) + "].");
  }
  BodyContactParams contact;
  contact.friction = 0;
  contact.static_friction = 0;
  contact.restitution = 0;
  Trajectory recording =
      simulate_trajectory(model, initial_state(model), {}, "implicit_euler", kAdjointFitDt,
                          testing::kFrameInterval, testing::kDuration, true, {}, contact);
  for (int type = 0; type < kSpringTypeCount; ++type)
    recording.model.springs.set_coefficients(static_cast<SpringType>(type), {1400, 30});
  FitOptions options;
  options.gradients = FitGradients::kAdjoint;
  options.compute_covariance = false;
  const FitResult result = fit_recording(recording, options);
  std::cout << result.report();
  EXPECT_EQ(result.gradient_path, "adjoint");
  EXPECT_TRUE(result.converged) << result.report();
  EXPECT_NEAR(result.at("ks").value, 1000, 0.01 * 1000) << result.report();
  EXPECT_NEAR(result.at("kd").value, 20, 0.01 * 20) << result.report();
}

// The windows' adjoint passes shared between threads: the same fit, bit for bit, on 1, 2 and 3
// threads.
TEST(FitAdjoint, ThreadsOverWindowsGiveTheSameFit) {
  const Trajectory recording = implicit_recording(true);
  FitOptions options;
  options.gradients = FitGradients::kAdjoint;
  options.compute_covariance = false;
  options.max_iterations = 8;
  const FitResult one = fit_recording(recording, options);
  for (const int threads : {1, 2, 3}) {
    options.num_threads = threads;
    const FitResult many = fit_recording(recording, options);
    EXPECT_EQ(many.gradient_path, "adjoint");
    EXPECT_EQ(many.final_cost, one.final_cost) << threads;
    EXPECT_EQ(many.at("ks").value, one.at("ks").value) << threads;
    EXPECT_EQ(many.at("kd").value, one.at("kd").value) << threads;
    EXPECT_EQ(many.adjoint_passes, one.adjoint_passes) << threads;
  }
}

TEST(FitAdjoint, NumericNamesAreParsed) {
  EXPECT_EQ(fit_gradients_from_name("auto", "gradients"), FitGradients::kAuto);
  EXPECT_EQ(fit_gradients_from_name("adjoint", "gradients"), FitGradients::kAdjoint);
  EXPECT_EQ(fit_gradients_from_name("numeric", "gradients"), FitGradients::kNumeric);
  try {
    fit_gradients_from_name("exact", "--gradients");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--gradients = exact is invalid: one of auto, adjoint, numeric");
  }
}

// 1 mm noise: both paths find the same minimum, and their restart-aware standard deviations
// agree (the adjoint's noise trace is a 16-probe estimate, hence the loose bound).
void expect_paths_agree(bool velocities) {
  Trajectory recording = implicit_recording(false, velocities);
  testing::add_noise(recording, 1e-3);
  FitOptions options;
  options.gradients = FitGradients::kNumeric;
  const FitResult numeric = fit_recording(recording, options);
  options.gradients = FitGradients::kAdjoint;
  const FitResult exact = fit_recording(recording, options);
  std::cout << numeric.report() << exact.report();
  ASSERT_TRUE(numeric.covariance_ok) << numeric.report();
  ASSERT_TRUE(exact.covariance_ok) << exact.report();
  for (const char* name : {"ks", "kd"}) {
    const FittedParameter& a = numeric.at(name);
    const FittedParameter& b = exact.at(name);
    EXPECT_NEAR(a.value, b.value, 0.05 * a.stddev) << name;
    EXPECT_NEAR(a.stddev_independent, b.stddev_independent, 0.02 * a.stddev_independent) << name;
    EXPECT_NEAR(a.stddev, b.stddev, 0.15 * a.stddev) << name;
  }
}

TEST(FitAdjoint, NoisyRecordingBothPathsAgree) { expect_paths_agree(true); }

TEST(FitAdjoint, NoisyRecordingWithoutVelocitiesBothPathsAgree) { expect_paths_agree(false); }

}  // namespace
}  // namespace jelly
