// The discrete adjoint of implicit_euler (solvers/adjoint/): every kind of gradient against
// central finite differences of the simulator's own runs (adjoint_checks.hpp), on a pinned cloth
// driven by a control sequence, a cube resting on a coulomb slope and two cubes on a floor; CG's
// backward pass; and the refusals of what it does not differentiate.
#include <cmath>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/solvers/adjoint/detail/implicit_euler_adjoint.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

#include "solvers/adjoint/adjoint_checks.hpp"
#include "support/systems.hpp"

namespace jelly {
namespace {

TEST(ImplicitEulerAdjoint, PinnedClothEveryKindAgreesWithFiniteDifferences) {
  const AdjointCase c = pinned_cloth();
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
  const GradientResult g = gradient_of(c);
  EXPECT_EQ(g.backward_solver, "cholmod");
  EXPECT_EQ(g.contact_steps, 0);
}

// A 3 x 3 x 3 cube resting on the 20-degree coulomb slope (friction enough to stick, no bounce).
AdjointCase cube_on_slope() {
  AdjointCase c;
  c.steps = 8;
  Model model = build_cube(testing::small_cube(3, 0.6));
  model.mass.setConstant(0.2);
  for (int t = 0; t < kSpringTypeCount; ++t)
    model.springs.set_coefficients(static_cast<SpringType>(t), {400.0 + 100 * t, 4.0 + t});
  const State s0 = jittered(testing::cube_on_slope(model, 20), 1e-4, 0.005);
  c.make = [model, s0] {
    Simulator sim = testing::make_sim(model, s0, "implicit_euler", 1.0 / 100);
    ContactParams contact;
    contact.friction = 3;
    contact.static_friction = 3;
    contact.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
    return sim;
  };
  return c;
}

TEST(ImplicitEulerAdjoint, CubeOnACoulombSlopeAgreesWithFiniteDifferences) {
  const AdjointCase c = cube_on_slope();
  const GradientResult g = gradient_of(c);
  EXPECT_GT(g.contact_steps, 9 * c.steps / 2);  // the bottom layer rests on the slope
  EXPECT_EQ(g.bounce_steps, 0);
  EXPECT_EQ(g.slide_steps, 0);
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
}

// The cube sliding down a slope of little friction (mu = 0.2 < tan 20 degrees), from a state
// 15 steps into the slide: every step's friction viscosity is set by the previous step's solve
// (traced through it), the first one's before the run (a constant).
AdjointCase sliding_cube(Real mu = 0.2) {
  AdjointCase c;
  c.steps = 10;
  Model model = build_cube(testing::small_cube(3, 0.6));
  model.mass.setConstant(0.2);
  for (int t = 0; t < kSpringTypeCount; ++t)
    model.springs.set_coefficients(static_cast<SpringType>(t), {400.0 + 100 * t, 4.0 + t});
  const State s0 = jittered(testing::cube_on_slope(model, 20), 1e-4, 0.005);
  c.make = [model, s0, mu] {
    Simulator sim = testing::make_sim(model, s0, "implicit_euler", 1.0 / 100);
    ContactParams contact;
    contact.friction = mu;
    contact.static_friction = mu;
    contact.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
    for (int k = 0; k < 15; ++k) sim.step();
    return sim;
  };
  return c;
}

TEST(ImplicitEulerAdjoint, CubeSlidingDownASlopeAgreesWithFiniteDifferences) {
  const AdjointCase c = sliding_cube();
  const GradientResult g = gradient_of(c);
  EXPECT_GE(g.contact_steps, 9 * c.steps);  // the bottom layer slides all the way
  EXPECT_EQ(g.slide_steps, 9);              // held: only the first step's, set before the run
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
}

// Two cubes of different materials resting side by side on a floor.
AdjointCase two_cubes_on_a_floor() {
  AdjointCase c;
  c.steps = 10;
  Model model;
  for (int b = 0; b < 2; ++b) {
    BodySpec spec;
    spec.name = b == 0 ? "left" : "right";
    CubeShape shape;
    shape.n = 3;
    shape.edge_length = 0.5;
    shape.origin = Vec3(b == 0 ? -0.8 : 0.3, 0.002, 0);
    spec.shape = shape;
    spec.material.particle_mass = b == 0 ? 0.1 : 0.3;
    spec.material.springs.fill({b == 0 ? 300.0 : 800.0, b == 0 ? 1.0 : 3.0});
    spec.velocity = Vec3(b == 0 ? 0.2 : -0.1, -0.3, 0);
    add_body(model, spec, "bodies[" + std::to_string(b) + "].");
  }
  c.make = [model] {
    Simulator sim = testing::make_sim(model, jittered(initial_state(model), 2e-4, 0.02),
                                      "implicit_euler", 1.0 / 100);
    ContactParams contact;
    contact.friction = 3;
    contact.static_friction = 3;
    contact.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), contact));
    return sim;
  };
  return c;
}

TEST(ImplicitEulerAdjoint, TwoCubesOnAFloorAgreeWithFiniteDifferencesPerBody) {
  const AdjointCase c = two_cubes_on_a_floor();
  const GradientResult g = gradient_of(c);
  EXPECT_GT(g.contact_steps, 0);
  EXPECT_EQ(g.bounce_steps, 0);
  EXPECT_EQ(g.slide_steps, 0);
  check_every_kind(c, 1, {SpringType::kStructural, SpringType::kBending});
}

// Two cubes of different materials, one resting on the other on a sticky coulomb floor, the
// upper one landing 0.5 mm above the lower one's top layer and moving sideways at `speed`:
// contact pairs between the bodies inside the solve at every step (the terrain's contacts in
// the same solve), friction `mu` between the bodies (0: frictionless, every pair slides without
// a viscosity; 3: every pair sticks), no restitution; `warmup` steps run before the
// differentiated run (whose first step's friction viscosities are then the state's).
AdjointCase cubes_in_contact(Real mu, Real speed, int warmup = 0) {
  AdjointCase c;
  c.steps = 10;
  Model model;
  for (int b = 0; b < 2; ++b) {
    BodySpec spec;
    spec.name = b == 0 ? "lower" : "upper";
    CubeShape shape;
    shape.n = 3;
    shape.edge_length = 0.3;
    shape.origin = Vec3(0, b == 0 ? 0.002 : 0.302 + 0.1505, 0);
    spec.shape = shape;
    spec.material.particle_mass = b == 0 ? 0.3 : 0.1;
    spec.material.springs.fill({b == 0 ? 800.0 : 300.0, b == 0 ? 3.0 : 1.0});
    spec.velocity = Vec3(b == 0 ? 0 : speed, b == 0 ? 0 : -0.05, 0);
    add_body(model, spec, "bodies[" + std::to_string(b) + "].");
  }
  c.make = [model, mu, warmup] {
    Simulator sim = testing::make_sim(model, jittered(initial_state(model), 2e-4, 0.01),
                                      "implicit_euler", 1.0 / 100);
    ContactParams floor;
    floor.friction = 3;
    floor.static_friction = 3;
    floor.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), floor));
    BodyContactParams contact;
    contact.friction = mu;
    contact.static_friction = mu;
    contact.restitution = 0;
    sim.set_body_contact(contact);
    for (int k = 0; k < warmup; ++k) EXPECT_TRUE(sim.step().ok);
    return sim;
  };
  return c;
}

TEST(ImplicitEulerAdjoint, FrictionlessCubesInContactAgreeWithFiniteDifferences) {
  const AdjointCase c = cubes_in_contact(0, 0.1);
  const GradientResult g = gradient_of(c);
  EXPECT_GE(g.pair_steps, 8 * c.steps);  // the facing layers touch (nearly) all along
  EXPECT_GT(g.contact_steps, 0);
  EXPECT_EQ(g.pair_bounce_steps, 0);
  EXPECT_EQ(g.pair_projected_steps, 0);
  EXPECT_EQ(g.pair_slide_steps, 0);  // sliding without friction: nothing held
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
  check_every_kind(c, 1, {SpringType::kStructural, SpringType::kBending});
}

TEST(ImplicitEulerAdjoint, StickingCubesInContactAgreeWithFiniteDifferences) {
  const AdjointCase c = cubes_in_contact(3, 0.1, 3);
  const GradientResult g = gradient_of(c);
  EXPECT_GE(g.pair_steps, 8 * c.steps);
  EXPECT_EQ(g.pair_bounce_steps, 0);
  EXPECT_EQ(g.pair_projected_steps, 0);
  EXPECT_EQ(g.pair_slide_steps, 0);
  // (The lower cube, held by the floor and the upper one, barely feels its structural springs:
  // that gradient is at the central differences' round-off, so its shear springs are checked.)
  check_every_kind(c, 0, {SpringType::kShear});
  check_every_kind(c, 1, {SpringType::kStructural, SpringType::kBending});
}

// Sliding pairs (mu = 0.3, the upper cube at 0.3 m/s), from 4 steps into the contact: every step's
// friction viscosity is set by the previous step's final solve (traced through it), the first
// step's by the steps before the run (constants of the run).
TEST(ImplicitEulerAdjoint, SlidingCubesInContactAgreeWithFiniteDifferences) {
  const AdjointCase c = cubes_in_contact(0.3, 0.3, 4);
  const GradientResult g = gradient_of(c);
  EXPECT_GE(g.pair_steps, 8 * c.steps);
  EXPECT_EQ(g.pair_bounce_steps, 0);
  EXPECT_EQ(g.pair_projected_steps, 0);
  EXPECT_LE(g.pair_slide_steps, g.pair_steps / c.steps + 1);  // the first step's only
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear});
  check_every_kind(c, 1, {SpringType::kStructural, SpringType::kBending});
}

// The case with Newton's method on the backward-Euler equations (newton_iterations > 1),
// converged tightly: the adjoint of the converged step against finite differences of runs
// whose every step converged.
AdjointCase with_newton(AdjointCase c) {
  c.make = [make = c.make] {
    Simulator sim = make();
    ImplicitEulerOptions o;
    o.newton_iterations = 60;
    o.newton_tolerance = 1e-12;
    sim.set_integrator(std::make_unique<ImplicitEuler>(o));
    return sim;
  };
  return c;
}

TEST(ImplicitEulerAdjoint, NewtonOnAPinnedClothAgreesWithFiniteDifferences) {
  const AdjointCase c = with_newton(pinned_cloth());
  const GradientResult g = gradient_of(c);
  EXPECT_EQ(g.backward_solver, "sparse_lu");
  EXPECT_EQ(g.newton_unconverged_steps, 0);
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear, SpringType::kBending});
}

TEST(ImplicitEulerAdjoint, NewtonOnACoulombSlopeAgreesWithFiniteDifferences) {
  const AdjointCase c = with_newton(cube_on_slope());
  const GradientResult g = gradient_of(c);
  EXPECT_GT(g.contact_steps, 9 * c.steps / 2);
  EXPECT_EQ(g.slide_steps, 0);
  EXPECT_EQ(g.newton_unconverged_steps, 0);
  check_every_kind(c, 0, {SpringType::kStructural, SpringType::kShear});
}

TEST(ImplicitEulerAdjoint, NewtonWithCubesInContactAgreesWithFiniteDifferences) {
  for (const Real mu : {0.0, 3.0}) {
    SCOPED_TRACE("friction " + std::to_string(mu));
    const AdjointCase c = with_newton(cubes_in_contact(mu, 0.1, 3));
    const GradientResult g = gradient_of(c);
    EXPECT_GE(g.pair_steps, 8 * c.steps);
    EXPECT_EQ(g.pair_slide_steps, 0);
    EXPECT_EQ(g.newton_unconverged_steps, 0);
    check_every_kind(c, 1, {SpringType::kStructural, SpringType::kBending});
  }
}

// Newton above 1000 unknowns: after the matrix-free CG forward (the default there) the backward
// solve is the matrix-free BiCGSTAB with block Jacobi; after an assembled forward (CHOLMOD) it
// is BiCGSTAB on the assembled exact Jacobian (both to a tight cg_tolerance here).
TEST(ImplicitEulerAdjoint, NewtonWithBiCgStabAgreesWithFiniteDifferences) {
  for (const bool assembled : {false, true}) {
    SCOPED_TRACE(assembled ? "assembled" : "matrix-free");
    AdjointCase c;
    c.steps = 4;
    Model model = build_cube(testing::small_cube(7, 0.6));
    model.mass.setConstant(0.02);
    model.springs.set_coefficients(SpringType::kStructural, {400, 4});
    const State s0 = jittered(rest_state(model), 1e-2, 0.3);
    c.make = [model, s0, assembled] {
      ImplicitEulerOptions o;
      o.newton_iterations = 60;
      o.newton_tolerance = 1e-10;
      o.cg_tolerance = 1e-13;
      if (assembled) o.linear_solver = ImplicitLinearSolver::kCholmod;
      SimulatorOptions so;
      so.dt = 0.01;
      return Simulator(model, s0, std::make_unique<ImplicitEuler>(o), so);
    };
    const GradientResult g = gradient_of(c);
    EXPECT_EQ(g.backward_solver,
              assembled ? "bicgstab_jacobi" : "bicgstab_block_jacobi_matrix_free");
    EXPECT_EQ(g.newton_unconverged_steps, 0);
    if (!assembled) {
      EXPECT_GT(g.backward_iterations, 0);
    }
    check_every_kind(c, 0, {SpringType::kStructural});
  }
}

// Newton after a matrix-free CG forward with contacts (the cube sticking on the slope, and
// sliding down a frictionless one: Newton's viscosities are held, so none here): the
// matrix-free BiCGSTAB backward solve filtered by the constraints.
TEST(ImplicitEulerAdjoint, NewtonMatrixFreeWithContactsAgreesWithFiniteDifferences) {
  for (const bool sliding : {false, true}) {
    SCOPED_TRACE(sliding ? "sliding" : "sticking");
    AdjointCase c = sliding ? sliding_cube(0) : cube_on_slope();
    const std::function<Simulator()> direct = c.make;
    c.make = [direct] {
      Simulator sim = direct();
      ImplicitEulerOptions o;
      o.newton_iterations = 60;
      o.newton_tolerance = 1e-12;
      o.linear_solver = ImplicitLinearSolver::kCg;
      o.cg_tolerance = 1e-13;
      sim.set_integrator(std::make_unique<ImplicitEuler>(o));
      return sim;
    };
    const GradientResult g = gradient_of(c);
    EXPECT_EQ(g.backward_solver, "bicgstab_block_jacobi_matrix_free");
    EXPECT_EQ(g.newton_unconverged_steps, 0);
    EXPECT_GT(g.contact_steps, 9 * c.steps / 2);
    EXPECT_EQ(g.slide_steps, 0);
    check_every_kind(c, 0, {SpringType::kShear});
  }
}

// CG forward and backward (tight tolerance): the gradient agrees to CG's accuracy.
TEST(ImplicitEulerAdjoint, ConjugateGradientsBackwardAgreesWithFiniteDifferences) {
  AdjointCase c = cube_on_slope();
  const std::function<Simulator()> direct = c.make;
  c.make = [direct] {
    Simulator sim = direct();
    ImplicitEulerOptions o;
    o.linear_solver = ImplicitLinearSolver::kCg;
    o.cg_tolerance = 1e-12;
    sim.set_integrator(std::make_unique<ImplicitEuler>(o));
    return sim;
  };
  const GradientResult g = gradient_of(c);
  EXPECT_EQ(g.backward_solver, "cg_jacobi_matrix_free");
  const GradientResult exact = gradient_of(cube_on_slope());
  for (int t = 0; t < kSpringTypeCount; ++t) {
    EXPECT_NEAR(g.ks[t], exact.ks[t], 1e-7 * std::abs(exact.ks[t]));
    EXPECT_NEAR(g.kd[t], exact.kd[t], 1e-7 * std::abs(exact.kd[t]));
  }
  EXPECT_LT((g.initial_velocity - exact.initial_velocity).norm(),
            1e-7 * exact.initial_velocity.norm());
  check_every_kind(c, 0, {SpringType::kShear});
  // An assembled CG forward (lagged Cholesky preconditioner): the same in its backward pass.
  c.make = [direct] {
    Simulator sim = direct();
    ImplicitEulerOptions o;
    o.linear_solver = ImplicitLinearSolver::kCg;
    o.cg_preconditioner = CgPreconditionerKind::kCholmod;
    o.cg_tolerance = 1e-12;
    sim.set_integrator(std::make_unique<ImplicitEuler>(o));
    return sim;
  };
  const GradientResult lagged = gradient_of(c);
  EXPECT_EQ(lagged.backward_solver, "cg_lagged_cholmod");
  EXPECT_LT((lagged.initial_velocity - exact.initial_velocity).norm(),
            1e-7 * exact.initial_velocity.norm());
  EXPECT_NEAR(lagged.kd[1], exact.kd[1], 1e-7 * std::abs(exact.kd[1]));
}

// Sliding contacts (low friction on the slope) are counted: the gradient through them holds the
// friction viscosity fixed. A loss at frame 0 adds its own derivatives to the initial state's.
TEST(ImplicitEulerAdjoint, CountsSlidingContactsAndTakesALossAtFrameZero) {
  const Model model = build_cube(testing::small_cube(3, 0.6));
  const State s0 = testing::cube_on_slope(model, 20);
  const auto make = [&] {
    Simulator sim = testing::make_sim(model, s0, "implicit_euler", 1.0 / 100);
    ContactParams contact;
    contact.friction = 0.05;
    contact.static_friction = 0.05;
    contact.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
    return sim;
  };
  GradientProblem p;
  p.steps = 10;
  p.loss_frames = {0, 10};
  p.loss = [](int frame, const State& s, VecX& dx, VecX&) {
    const Real w = frame == 0 ? 2.0 : 1.0;
    dx = VecX::Constant(s.x.size(), w);
    return w * s.x.sum();
  };
  Simulator sim = make();
  const GradientResult g = implicit_euler_gradient(sim, p);
  EXPECT_GT(g.slide_steps, 0);
  EXPECT_EQ(g.bounce_steps, 0);
  // Frame 0 alone: dL/dx0 = 2, dL/dv0 = 0.
  p.loss_frames = {0};
  Simulator again = make();
  const GradientResult only_start = implicit_euler_gradient(again, p);
  EXPECT_EQ(only_start.initial_position, VecX::Constant(s0.x.size(), 2.0));
  EXPECT_EQ(only_start.initial_velocity, VecX::Zero(s0.x.size()));
  EXPECT_DOUBLE_EQ(only_start.loss, 2 * s0.x.sum());
}

// Checkpoints every 5 steps (segments of 5, and a last one of 1): the segments recomputed from
// their snapshots give the stored run's gradient, and the simulator ends where the run ended.
TEST(ImplicitEulerAdjoint, CheckpointsGiveTheStoredRunsGradient) {
  for (const int which : {0, 1, 2}) {
    const bool matrix_free = which == 1;
    AdjointCase c = which == 0 ? pinned_cloth() : which == 1 ? cube_on_slope() : sliding_cube();
    if (matrix_free) {
      const std::function<Simulator()> direct = c.make;
      c.make = [direct] {
        Simulator sim = direct();
        ImplicitEulerOptions o;
        o.linear_solver = ImplicitLinearSolver::kCg;
        o.cg_tolerance = 1e-10;
        sim.set_integrator(std::make_unique<ImplicitEuler>(o));
        return sim;
      };
    }
    c.steps = 11;
    if (!c.targets.empty()) c.targets.resize(c.steps);
    Simulator stored_sim = c.make();
    const GradientResult stored = implicit_euler_gradient(stored_sim, problem_of(c, stored_sim));
    Simulator sim = c.make();
    GradientProblem p = problem_of(c, sim);
    p.checkpoint_every = 5;
    const GradientResult checkpointed = implicit_euler_gradient(sim, p);
    EXPECT_EQ(checkpointed.loss, stored.loss);
    EXPECT_EQ(checkpointed.initial_position, stored.initial_position);
    EXPECT_EQ(checkpointed.initial_velocity, stored.initial_velocity);
    EXPECT_EQ(checkpointed.ks, stored.ks);
    EXPECT_EQ(checkpointed.kd, stored.kd);
    EXPECT_EQ(checkpointed.particle_mass, stored.particle_mass);
    EXPECT_EQ(checkpointed.gravity, stored.gravity);
    EXPECT_EQ(checkpointed.pin_targets, stored.pin_targets);
    EXPECT_EQ(sim.state().x, stored_sim.state().x);
    EXPECT_EQ(sim.state().t, stored_sim.state().t);
  }
}

// The cube on the coulomb slope with the model's external forces.
AdjointCase forced_cube_on_slope(const Model& model) {
  AdjointCase c = cube_on_slope();
  const State s0 = jittered(testing::cube_on_slope(model, 20), 1e-4, 0.005);
  c.make = [model, s0] {
    Simulator sim = testing::make_sim(model, s0, "implicit_euler", 1.0 / 100);
    ContactParams contact;
    contact.friction = 3;
    contact.static_friction = 3;
    contact.restitution = 0;
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
    return sim;
  };
  return c;
}

// A constant force (spread by mass, over particles of unequal masses), wind and point forces,
// gusting, on the cube resting on the slope: every force parameter, and the others through them
// (masses through the spread, initial velocities through the drag).
TEST(ImplicitEulerAdjoint, ExternalForcesOnASlopeAgreeWithFiniteDifferences) {
  Model model = build_cube(testing::small_cube(3, 0.6));
  model.mass.setConstant(0.2);
  for (int t = 0; t < kSpringTypeCount; ++t)
    model.springs.set_coefficients(static_cast<SpringType>(t), {400.0 + 100 * t, 4.0 + t});
  model.external_forces = gusting_forces();
  check_external_forces(forced_cube_on_slope, model);
  const AdjointCase c = forced_cube_on_slope(model);
  check_every_kind(c, 0, {SpringType::kShear});
  // The spread by mass: the gradient of a body's mass when the pushed particles' masses differ.
  Model uneven = model;
  uneven.mass[0] = 0.35;
  uneven.mass[9] = 0.1;
  check_external_forces(forced_cube_on_slope, uneven);
}

// Wind on a pinned cloth whose gust starts inside the run (start = 0.05 s): the CG backward pass
// (matrix-free, the drag on its diagonal) against central differences, every kind included.
TEST(ImplicitEulerAdjoint, WindOnAPinnedClothAgreesWithFiniteDifferences) {
  const AdjointCase base = pinned_cloth();
  Simulator probe = base.make();
  Model model = probe.model();
  ExternalForce wind;
  wind.kind = ExternalForceKind::kWind;
  for (int i = 0; i < model.num_particles(); ++i) wind.particles.push_back(i);
  wind.vector = Vec3(0.5, 0.1, 2);
  wind.drag = 0.02;
  wind.gust = 0.5;
  wind.gust_frequency = 1.5;
  wind.start = 0.05;
  model.external_forces = {wind};
  const State s0 = probe.state();
  for (const bool cg : {false, true}) {
    const auto make_case = [&base, s0, cg](const Model& m) {
      AdjointCase c = base;
      c.make = [m, s0, cg] {
        Simulator sim = testing::make_sim(m, s0, "implicit_euler", 1.0 / 60);
        if (cg) {
          ImplicitEulerOptions o;
          o.linear_solver = ImplicitLinearSolver::kCg;
          o.cg_tolerance = 1e-13;
          sim.set_integrator(std::make_unique<ImplicitEuler>(o));
        }
        return sim;
      };
      return c;
    };
    check_external_forces(make_case, model);
    check_every_kind(make_case(model), 0, {SpringType::kStructural});
    if (cg) {
      EXPECT_EQ(gradient_of(make_case(model)).backward_solver.rfind("cg", 0), 0u);
    }
  }
}

TEST(ImplicitEulerAdjoint, RefusesWhatItDoesNotDifferentiate) {
  const Model model = build_cube(testing::small_cube(2, 0.5));
  GradientProblem p;
  p.steps = 2;
  p.loss = [](int, const State& s, VecX& dx, VecX&) {
    dx.setOnes();
    return s.x.sum();
  };
  {
    Simulator sim = testing::make_sim(model, rest_state(model), "rk4", 1e-3);
    EXPECT_THROW(implicit_euler_gradient(sim, p), InputError);
  }
  {
    Simulator sim = testing::make_sim(model, rest_state(model), "implicit_euler", 0.01);
    ContactParams seed;
    seed.model = ContactModel::kSeed;
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), seed));
    EXPECT_THROW(implicit_euler_gradient(sim, p), InputError);
  }
  {  // contact between bodies resolved after the step
    Model two;
    for (int b = 0; b < 2; ++b) {
      BodySpec spec;
      spec.name = b == 0 ? "a" : "b";
      CubeShape shape;
      shape.n = 2;
      shape.edge_length = 0.5;
      shape.origin = Vec3(b == 0 ? -1.0 : 1.0, 0, 0);
      spec.shape = shape;
      add_body(two, spec, "bodies[" + std::to_string(b) + "].");
    }
    ImplicitEulerOptions o;
    o.contact = ImplicitContactMode::kAfterStep;
    SimulatorOptions so;
    so.dt = 0.01;
    Simulator sim(two, initial_state(two), std::make_unique<ImplicitEuler>(o), so);
    EXPECT_THROW(implicit_euler_gradient(sim, p), InputError);
  }
  {
    Simulator sim = testing::make_sim(model, rest_state(model), "implicit_euler", 0.01);
    GradientProblem wrong = p;
    wrong.driven_pins = {0};  // not pinned
    wrong.pin_targets.assign(2, Vec3::Zero());
    EXPECT_THROW(implicit_euler_gradient(sim, wrong), InputError);
  }
}

}  // namespace
}  // namespace jelly
