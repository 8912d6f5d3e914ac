// fit_recording on exact gradients (the adjoint of implicit_euler): coefficients recovered from
// synthetic implicit_euler recordings, the path named in the report, the numeric path as the
// fallback for what the adjoint refuses, and both paths agreeing on a noisy recording.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/fit/spring_fit.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/terrain/plane.hpp>

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

// On the slope the replays restart with the recording run's contact state (its friction
// viscosities, set by the solve before, recorded per frame), so the cost is 0 at the truth (it
// was not while windows restarted afresh); the sliding contacts' viscosities are held by the
// adjoint. Both paths must find the same minimum, the truth.
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
    EXPECT_NEAR(exact.at(name).value, truth, 1e-4 * truth) << name;
    EXPECT_NEAR(exact.at(name).value, numeric.at(name).value, 1e-4 * truth) << name;
  }
  EXPECT_LE(exact.final_cost, 1e-20);
  EXPECT_LE(numeric.final_cost, 1e-20);
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

// Two cubes colliding in the air (contact between the bodies inside the solve, no restitution)
// with friction `mu`.
Trajectory colliding_cubes(Real mu) {
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
    spec.velocity = Vec3(b == 0 ? 1.5 : 0, b == 0 ? 0.3 : 0, 0);
    add_body(model, spec, "bodies[" + std::to_string(b) + "].");
  }
  BodyContactParams contact;
  contact.friction = mu;
  contact.static_friction = mu;
  contact.restitution = 0;
  Trajectory recording =
      simulate_trajectory(model, initial_state(model), {}, "implicit_euler", kAdjointFitDt,
                          testing::kFrameInterval, testing::kDuration, true, {}, contact);
  for (int type = 0; type < kSpringTypeCount; ++type)
    recording.model.springs.set_coefficients(static_cast<SpringType>(type), {1400, 30});
  return recording;
}

// A cube sliding (mu 0.3, at 0.3 m/s) on another that rests on a sticky coulomb floor: pairs
// between the bodies in contact all along, each step's friction viscosity set by the step
// before (what a window started afresh does not have).
Trajectory stacked_cubes() {
  Model model;
  for (int b = 0; b < 2; ++b) {
    BodySpec spec;
    spec.name = b == 0 ? "lower" : "upper";
    CubeShape shape;
    shape.n = 3;
    shape.edge_length = 0.3;
    shape.origin = Vec3(0, b == 0 ? 0.002 : 0.4525, 0);
    spec.shape = shape;
    spec.material.particle_mass = b == 0 ? 0.3 : 0.1;
    spec.material.springs = kTruth;
    spec.velocity = Vec3(b == 0 ? 0 : 0.3, b == 0 ? 0 : -0.05, 0);
    add_body(model, spec, "bodies[" + std::to_string(b) + "].");
  }
  BodyContactParams contact;
  contact.friction = 0.3;
  contact.static_friction = 0.3;
  contact.restitution = 0;
  const TerrainFactory floor = [] {
    ContactParams params;
    params.friction = 3;
    params.static_friction = 3;
    params.restitution = 0;
    Terrains terrains;
    terrains.push_back(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), params));
    return terrains;
  };
  return simulate_trajectory(model, initial_state(model), floor, "implicit_euler", kAdjointFitDt,
                             testing::kFrameInterval, 0.3, true, {}, contact);
}

// The windows' replays at the truth: with the recording's carried contact state at each window's
// start they are the recording; started afresh (a recording without the states) they are not.
TEST(FitAdjoint, WindowsStartWithTheRecordingsCarriedContactState) {
  const Trajectory recording = stacked_cubes();
  const Real window = FitOptions().window;
  const Real stored = replay_cost(recording, window);
  Trajectory without = recording;
  without.integrator_states.clear();
  const Real afresh = replay_cost(without, window);
  std::cout << "replay cost at the truth: stored " << stored << ", afresh " << afresh << " m^2\n";
  EXPECT_EQ(stored, 0);
  EXPECT_GT(afresh, 1e-8);
}

// The adjoint path fits through the contact, frictionless and with friction. Each window starts
// with the contact pairs the recording's run carried into its first frame (stored), or afresh
// (without the states, as a `jelly run` recording): in these collisions both recover the truth.
TEST(FitAdjoint, RecoversKsAndKdThroughContactBetweenBodies) {
  for (const Real mu : {0.0, 0.5}) {
    for (const bool stored : {true, false}) {
      SCOPED_TRACE("friction " + std::to_string(mu) + (stored ? ", stored" : ", afresh"));
      Trajectory recording = colliding_cubes(mu);
      if (!stored) recording.integrator_states.clear();
      FitOptions options;
      options.gradients = FitGradients::kAdjoint;
      options.compute_covariance = false;
      const FitResult result = fit_recording(recording, options);
      std::cout << result.report();
      EXPECT_EQ(result.gradient_path, "adjoint");
      EXPECT_TRUE(result.converged) << result.report();
      EXPECT_NEAR(result.at("ks").value, 1000, 1e-4 * 1000) << result.report();
      EXPECT_NEAR(result.at("kd").value, 20, 1e-4 * 20) << result.report();
    }
  }
}

// A fit of the stacked cubes (a sliding pair between the bodies all along) recovers the truth
// when its windows start with the recorded contact state; started afresh (as before, and as a
// recording without the states still is) its minimum is off the truth.
TEST(FitAdjoint, RecoversKsAndKdThroughSlidingContactWithTheRecordedState) {
  Trajectory recording = stacked_cubes();
  for (int type = 0; type < kSpringTypeCount; ++type)
    recording.model.springs.set_coefficients(static_cast<SpringType>(type), {1400, 30});
  FitOptions options;
  options.gradients = FitGradients::kNumeric;
  options.compute_covariance = false;
  const FitResult result = fit_recording(recording, options);
  std::cout << result.report();
  EXPECT_TRUE(result.converged) << result.report();
  EXPECT_NEAR(result.at("ks").value, 1000, 1e-4 * 1000) << result.report();
  EXPECT_NEAR(result.at("kd").value, 20, 1e-4 * 20) << result.report();
  recording.integrator_states.clear();
  const FitResult afresh = fit_recording(recording, options);
  std::cout << afresh.report();
  EXPECT_GT(afresh.final_cost, 1e-10) << afresh.report();
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
