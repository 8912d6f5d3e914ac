// The adjoint of projective_dynamics' fixed point (solvers/adjoint/): every kind of gradient
// against central finite differences of the simulator's own runs (adjoint_checks.hpp), the
// iterations run to convergence (the gradient is that of the converged steps), on a free cube
// with external forces and on a pinned cloth driven by a control sequence; the refusals.
#include <memory>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/adjoint/detail/projective_dynamics_adjoint.hpp>
#include <jelly/solvers/integrators/detail/projective_dynamics.hpp>
#include <jelly/terrain/plane.hpp>

#include "solvers/adjoint/adjoint_checks.hpp"
#include "support/systems.hpp"

namespace jelly {
namespace {

// Iterations enough for the steps below to converge to round-off (a fixed count, so that the
// run is a smooth function of its parameters for the finite differences).
ProjectiveDynamicsOptions converged_pd() {
  ProjectiveDynamicsOptions o;
  o.iterations = 600;
  return o;
}

Simulator pd_sim(const Model& model, const State& s0, Real dt) {
  Simulator sim = testing::make_sim(model, s0, "projective_dynamics", dt);
  sim.set_integrator(std::make_unique<ProjectiveDynamics>(converged_pd()));
  return sim;
}

// A 3 x 3 x 3 cube tumbling freely (moved off rest, spinning) under `model`'s forces.
AdjointCase free_cube(const Model& model) {
  AdjointCase c;
  c.steps = 10;
  State s0 = jittered(rest_state(model), 0.01, 0.1);
  for (int i = 0; i < model.num_particles(); ++i)
    particle(s0.v, i) += Vec3(0.5, 1, 0).cross(particle(s0.x, i));
  c.make = [model, s0] { return pd_sim(model, s0, 1.0 / 100); };
  return c;
}

Model small_cube_model() {
  Model model = build_cube(testing::small_cube(3, 0.6));
  model.mass.setConstant(0.2);
  for (int t = 0; t < kSpringTypeCount; ++t)
    model.springs.set_coefficients(static_cast<SpringType>(t), {400.0 + 100 * t, 4.0 + t});
  return model;
}

TEST(ProjectiveDynamicsAdjoint, FreeCubeEveryKindAgreesWithFiniteDifferences) {
  const AdjointCase c = free_cube(small_cube_model());
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
  const GradientResult g = gradient_of(c);
  EXPECT_EQ(g.backward_solver, "bicgstab_pd_prefactored");
  EXPECT_GT(g.backward_iterations, 0);
  EXPECT_LT(g.forward_residual, 1e-10);  // the forward converged: its gradient is the run's
  EXPECT_EQ(g.contact_steps, 0);
}

// A constant force spread by mass, wind starting inside the run and a point force, all gusting:
// every force parameter, the others with them, and the forces over particles of unequal masses.
TEST(ProjectiveDynamicsAdjoint, ExternalForcesAgreeWithFiniteDifferences) {
  Model model = small_cube_model();
  model.external_forces = gusting_forces(0.04);  // (the wind starts inside the run)
  check_external_forces(free_cube, model);
  check_every_kind(free_cube(model), 0, {SpringType::kShear});
  // The spread by mass: the masses' gradient when the pushed particles' masses differ (the
  // forces' parameters; set_particle_mass would even the masses out).
  Model uneven = model;
  uneven.mass[0] = 0.35;
  uneven.mass[9] = 0.1;
  check_external_forces(free_cube, uneven);
}

// The 6 x 6 cloth pinned at two corners, one driven along a sampled circle: every kind, the
// pins' targets included.
TEST(ProjectiveDynamicsAdjoint, PinnedClothEveryKindAgreesWithFiniteDifferences) {
  AdjointCase c = pinned_cloth("projective_dynamics");
  const auto make = c.make;
  c.make = [make] {
    Simulator sim = make();
    sim.set_integrator(std::make_unique<ProjectiveDynamics>(converged_pd()));
    return sim;
  };
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
  const GradientResult g = gradient_of(c);
  EXPECT_LT(g.forward_residual, 1e-10);
  // The same gradient from checkpoints every 5 steps (the forward runs again bit for bit).
  Simulator sim = c.make();
  GradientProblem p = problem_of(c, sim);
  p.checkpoint_every = 5;
  const GradientResult again = integrator_gradient(sim, p);
  EXPECT_EQ(again.initial_velocity, g.initial_velocity);
  EXPECT_EQ(again.pin_targets, g.pin_targets);
  EXPECT_EQ(again.ks, g.ks);
}

TEST(ProjectiveDynamicsAdjoint, RefusesWhatItDoesNotDifferentiate) {
  const Model model = small_cube_model();
  GradientProblem p;
  p.steps = 2;
  p.loss = [](int, const State&, VecX&, VecX&) { return 0.0; };
  {
    Simulator sim = pd_sim(model, rest_state(model), 0.01);
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3(0, -5, 0), ContactParams{})));
    EXPECT_THROW(integrator_gradient(sim, p), InputError);
  }
  {
    Simulator sim = testing::make_sim(model, rest_state(model), "rk4", 0.001);
    EXPECT_THROW(integrator_gradient(sim, p), InputError);
    EXPECT_THROW(projective_dynamics_gradient(sim, p), InputError);
  }
  EXPECT_TRUE(has_adjoint("projective_dynamics"));
  EXPECT_FALSE(has_adjoint("xpbd"));
}

}  // namespace
}  // namespace jelly
