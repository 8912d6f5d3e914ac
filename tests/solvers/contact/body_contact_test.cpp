// Contact between bodies and within a body: the broad phase finds exactly the pairs of a brute
// force search; the response conserves momentum; two free cubes collide and separate, a stack
// comes to rest without overlap for every integrator; spring neighbours never collide.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/broad_phase.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::make_sim;
using Pairs = std::vector<BroadPhase::Pair>;

Pairs brute_force(const VecX& x, const VecX& r) {
  Pairs pairs;
  for (int i = 0; i < r.size(); ++i)
    for (int j = i + 1; j < r.size(); ++j) {
      const Real reach = r[i] + r[j];
      if ((particle(x, j) - particle(x, i)).squaredNorm() < reach * reach) pairs.emplace_back(i, j);
    }
  return pairs;
}

// Random clouds of different densities, sizes and radii (negative coordinates, coincident
// points, a lone large particle): the same pairs as a brute-force search, each once.
// Huge, infinite and NaN coordinates (a diverging run, a damaged checkpoint) get a cell too:
// converting them to an int cell index was undefined behaviour (jelly_checkpoint_fuzzer). Only
// the two particles within reach pair up.
TEST(BroadPhase, HugeAndNonFiniteCoordinatesPairWithNothing) {
  const Real inf = std::numeric_limits<Real>::infinity();
  VecX x(3 * 6);
  x << 0, 0, 0, 0.5, 0, 0, 1e300, 0, 0, -1e300, 1e300, 0, inf, 0, -inf, std::nan(""), 0, 0;
  const VecX radius = VecX::Constant(6, 0.3);
  BroadPhase broad;
  Pairs pairs;
  broad.find_pairs(x, radius, pairs);
  EXPECT_EQ(pairs, Pairs({{0, 1}}));
  // A NaN among finite coordinates did not widen the bounding box of the dense grid, and its
  // cell index was undefined (jelly_checkpoint_fuzzer, after the fix above).
  VecX y(3 * 3);
  y << 0, 0, 0, 0.5, 0, 0, std::nan(""), 0, 0;
  broad.find_pairs(y, VecX::Constant(3, 0.3), pairs);
  EXPECT_EQ(pairs, Pairs({{0, 1}}));
}

TEST(BroadPhase, FindsExactlyThePairsOfABruteForceSearch) {
  std::mt19937 rng(42);
  BroadPhase broad;
  Pairs pairs;
  for (const int n : {2, 10, 200, 1000, 3000}) {
    for (const Real extent : {0.5, 5.0, 50.0}) {
      std::uniform_real_distribution<Real> u(-extent, extent), radius(0.01, 0.2);
      VecX x(3 * n), r(n);
      for (int i = 0; i < n; ++i) {
        particle(x, i) = Vec3(u(rng), u(rng), u(rng));
        r[i] = radius(rng);
      }
      if (n >= 10) {
        particle(x, 3) = particle(x, 7);  // coincident
        r[5] = 1.0;                       // one large particle: larger cells
      }
      broad.find_pairs(x, r, pairs);
      Pairs sorted = pairs;
      std::sort(sorted.begin(), sorted.end());
      EXPECT_TRUE(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end());
      const Pairs expected = brute_force(x, r);  // sorted by construction
      EXPECT_EQ(sorted, expected) << "n = " << n << ", extent " << extent;
      if (n == 3000 && extent == 5.0) {
        EXPECT_GT(expected.size(), 100u);
      }
    }
  }
}

// Two small cubes side by side along x, `gap` apart, of edge 0.3 (4 per edge: radius 0.05).
Model two_cubes(Real gap, int n = 4, Real edge = 0.3) {
  Model model;
  const CubeSpec a = testing::small_cube(n, edge, Vec3(-edge - 0.5 * gap, 0, 0));
  const CubeSpec b = testing::small_cube(n, edge, Vec3(0.5 * gap, 0.1, 0.05));
  model.add_body("left", a.shape().build(a.material(), "a."));
  model.add_body("right", b.shape().build(b.material(), "b."));
  model.gravity.setZero();
  return model;
}

// One resolve on overlapping bodies with random velocities: momentum exactly conserved, angular
// momentum too without friction (friction's torque between particle centres is the one change),
// no energy gained.
TEST(BodyContact, ResponseConservesMomentum) {
  const Model model = two_cubes(-0.01);  // overlapping by 1 cm
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  State before = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i) {
    particle(before.v, i) =
        Vec3(u(rng), u(rng), u(rng)) + (i < 64 ? Vec3(2, 0, 0) : Vec3(-2, 0, 0));
  }
  for (const Real mu : {0.0, 0.5}) {
    BodyContactParams params;
    params.friction = params.static_friction = mu;
    params.restitution = 0.5;
    params.iterations = 50;  // enough passes to take the 4 cm overlap out entirely
    BodyContact contact(params);
    State s = before;
    contact.resolve(model, before, s, 1e-3);
    ASSERT_GT(contact.pairs().size(), 10u);
    const Vec3 p0 = linear_momentum(model, before), p1 = linear_momentum(model, s);
    const Vec3 l0 = angular_momentum(model, before), l1 = angular_momentum(model, s);
    const Real scale = model.mass.sum() * 2;  // total mass times the approach speed
    EXPECT_LT((p1 - p0).norm(), 1e-12 * scale) << mu;
    if (mu == 0) {
      EXPECT_LT((l1 - l0).norm(), 1e-12 * scale) << mu;
    }
    // No energy gained, and the overlap is gone (as much of it by the particles' projection as
    // the energy allows, the rest by translations of the bodies).
    EXPECT_LE(total_energy(model, s), total_energy(model, before) * (1 + 1e-12)) << mu;
    const auto deepest = [&](const VecX& x) {
      Real worst = 0;
      for (const auto& [i, j] : contact.pairs())
        worst = std::min(worst, (particle(x, j) - particle(x, i)).norm() - 0.1);
      return worst;
    };
    EXPECT_GT(deepest(s.x), -0.01 * 0.1) << mu;  // to the iterations' accuracy
  }
}

// Collision detection apart from integration: collide() before the step finds a set from which
// resolve() (after the step) and find_candidates() (the implicit solve's) take exactly the pairs
// a search of their own would find; a particle that travels beyond its reach makes them search.
TEST(BodyContact, CollideFindsThePairsEveryConsumerWouldFind) {
  const Model model = two_cubes(0.02);
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-1, 1);
  State before = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i) {
    particle(before.v, i) =
        Vec3(u(rng), u(rng), u(rng)) + (i < 64 ? Vec3(3, 0, 0) : Vec3(-3, 0, 0));
  }
  const Real h = 1.0 / 60;
  State after = before;
  after.x += h * before.v;  // a step's drift: the cubes overlap at its end
  BodyContactParams params;
  params.iterations = 10;
  BodyContact searched(params), collided(params);
  State by_search = after, by_collide = after;
  searched.resolve(model, before, by_search, h);
  collided.collide(model, before, h);
  ASSERT_GT(collided.collisions().size(), searched.pairs().size());
  collided.resolve(model, before, by_collide, h);
  ASSERT_GT(searched.pairs().size(), 10u);
  EXPECT_EQ(collided.pairs(), searched.pairs());
  EXPECT_EQ(collided.stats().collided, 1);
  EXPECT_EQ(collided.stats().searched, 0);
  EXPECT_EQ(searched.stats().searched, 1);
  // The same pairs in the same order: the same bits.
  EXPECT_EQ(by_collide.x, by_search.x);
  EXPECT_EQ(by_collide.v, by_search.v);

  // The implicit solve's candidates: its pads (the step's travel and a quarter radius) fit
  // within the reaches.
  const VecX pad = h * before.v.reshaped(3, model.num_particles()).colwise().norm().transpose();
  collided.collide(model, before, h);
  const Pairs from_set = collided.find_candidates(model, before.x, pad, 0.25);
  EXPECT_EQ(from_set, searched.find_candidates(model, before.x, pad, 0.25));
  EXPECT_EQ(collided.stats().collided, 2);

  // One particle thrown 1 m in the step: beyond its reach, so resolve() searches again.
  collided.collide(model, before, h);
  State far = after;
  particle(far.x, 0) += Vec3(1, 0, 0);
  collided.resolve(model, before, far, h);
  EXPECT_EQ(collided.stats().searched, 1);
  // A set serves once, and only the state it was found for.
  collided.collide(model, before, h);
  State moved = before;
  particle(moved.x, 3) += Vec3(1e-9, 0, 0);
  collided.find_candidates(model, moved.x, pad, 0.25);
  collided.find_candidates(model, before.x, pad, 0.25);
  EXPECT_EQ(collided.stats().searched, 3);
}

// Two free cubes thrown at each other off-centre without gravity: they collide and separate;
// linear momentum is conserved by every integrator (to 1e-9 relative) and, frictionless,
// angular momentum by symplectic Euler, which conserves it exactly between contacts.
class BodiesEveryIntegrator : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Registry, BodiesEveryIntegrator, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// Two free cubes thrown at each other; returns |L1 - L0| / |L0|.
Real collide_two_cubes(const std::string& integrator, Real dt, Real end = 0.5) {
  SCOPED_TRACE(integrator + " at dt = " + std::to_string(dt));
  const Model model = two_cubes(0.3);
  State s = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i)
    particle(s.v, i) = i < 64 ? Vec3(1.5, 0, 0) : Vec3(-1, 0, 0.1);
  Simulator sim = make_sim(model, s, integrator, dt);
  BodyContactParams params;
  params.friction = params.static_friction = 0;
  params.restitution = 0.5;
  sim.set_body_contact(params);
  const Vec3 p0 = linear_momentum(model, s), l0 = angular_momentum(model, s);
  long touching_steps = 0;
  testing::Probe probe(
      [&](const Simulator& sm) { touching_steps += sm.body_contact().pairs().empty() ? 0 : 1; });
  sim.add_observer(probe);
  EXPECT_TRUE(sim.run_until(end).ok());
  const Vec3 p1 = linear_momentum(model, sim.state()), l1 = angular_momentum(model, sim.state());
  EXPECT_GT(touching_steps, 0);
  EXPECT_TRUE(sim.body_contact().pairs().empty());  // apart again
  EXPECT_LT((p1 - p0).norm(), 1e-9 * p0.norm());
  // They bounced: their centres move apart. (At 1 ms the left cube even moves slower than the
  // centre of mass, 0.25 m/s; at large steps they also deflect each other vertically, the
  // contact normals being those of the start of each step.)
  Vec3 left = Vec3::Zero(), right = Vec3::Zero(), left_v = Vec3::Zero(), right_v = Vec3::Zero();
  for (int i = 0; i < 64; ++i) {
    left += particle(sim.state().x, i) / 64;
    right += particle(sim.state().x, i + 64) / 64;
    left_v += particle(sim.state().v, i) / 64;
    right_v += particle(sim.state().v, i + 64) / 64;
  }
  EXPECT_GT((right - left).dot(right_v - left_v), 0);
  if (dt <= 1e-3) {
    EXPECT_LT(left_v.x(), 0.25);
  }
  // Apart: no particle of one cube within the sum of the radii of one of the other.
  Real closest = 1e9;
  for (int i = 0; i < 64; ++i)
    for (int j = 64; j < 128; ++j)
      closest = std::min(closest, (particle(sim.state().x, j) - particle(sim.state().x, i)).norm());
  EXPECT_GT(closest, 0.1);
  return (l1 - l0).norm() / l0.norm();
}

TEST_P(BodiesEveryIntegrator, TwoFreeCubesCollideConserveMomentumAndSeparate) {
  const Real angular = collide_two_cubes(GetParam(), 1e-3);
  if (GetParam() == "symplectic_euler") {
    EXPECT_LT(angular, 1e-9);
  }
}

// implicit_euler with the pairs inside its solve, at its large steps.
TEST(BodyContact, ImplicitEulerTwoFreeCubesCollideAtLargeSteps) {
  for (const Real dt : {1.0 / 60, 1.0 / 30}) collide_two_cubes("implicit_euler", dt, 1.0);
}

// The integrators whose body contact is the after-step response and which are stable at a
// game's steps (the explicit ones diverge there on these cubes).
std::vector<std::string> after_step_integrators() {
  return {"arkode_dirk", "arkode_erk", "implicit_euler", "projective_dynamics", "vbd", "xpbd"};
}

// The after-step response never adds energy to a frictionless, inelastic collision at a game's
// steps: the total energy never rises above its start (the pairs taken one after another with
// the particles' projection gained energy: docs/contact.md has the figures).
TEST(BodyContact, AfterStepHeadOnCollisionNeverGainsEnergy) {
  for (const std::string& integrator : after_step_integrators())
    for (const Real dt : {1.0 / 60, 1.0 / 30}) {
      SCOPED_TRACE(integrator + " at dt = " + std::to_string(dt));
      Simulator sim = testing::head_on_cubes(integrator, dt, 0);
      const Real e0 = total_energy(sim.model(), sim.state());
      Real worst = 0;
      long touching = 0;
      while (sim.state().t < 1.0 - 0.5 * dt) {
        ASSERT_TRUE(sim.step().ok);
        worst = std::max(worst, total_energy(sim.model(), sim.state()) / e0);
        touching += sim.body_contact().pairs().empty() ? 0 : 1;
      }
      EXPECT_GT(touching, 0);
      EXPECT_LE(worst, 1 + 1e-9);
    }
}

// With restitution 1 and no dampers, at 1 ms: the integrators that keep energy (rk4, ARKODE's
// explicit and implicit Runge-Kutta) keep the collision's energy to 1 %; the others lose what
// their own damping takes, and none ever gains more than round-off.
// In a run, every step's contact takes its pairs from the collision phase: after the step
// (after_step) and inside implicit_euler's solve.
TEST(BodyContact, RunsTakeTheirPairsFromTheCollisionPhase) {
  for (const bool inside : {false, true}) {
    Simulator sim = testing::head_on_cubes("implicit_euler", 1.0 / 60, 0);
    if (inside) sim.set_integrator(make_integrator("implicit_euler"));
    const RunReport report = sim.run_until(0.3);
    // (During the impact the springs accelerate particles beyond the reach their velocity at
    // the step's start gave: those steps search again.)
    const Real collided = report.statistics.at("body_contact_collided_steps");
    EXPECT_GE(collided, 0.6 * report.steps) << inside;
    EXPECT_EQ(collided + report.statistics.at("body_contact_searched_steps"), report.steps)
        << inside;
    EXPECT_GT(report.statistics.at("body_contact_pairs"), 0) << inside;
  }
}

TEST(BodyContact, AfterStepElasticCollisionKeepsItsEnergy) {
  for (const char* integrator : {"arkode_dirk", "arkode_erk", "implicit_euler",
                                 "projective_dynamics", "rk4", "vbd", "xpbd"}) {
    SCOPED_TRACE(integrator);
    Simulator sim = testing::head_on_cubes(integrator, 1e-3, 1, 1, 0);
    const Real e0 = total_energy(sim.model(), sim.state());
    Real worst = 0, lowest = 1e9;
    long touching = 0;
    while (sim.state().t < 0.3) {
      ASSERT_TRUE(sim.step().ok);
      const Real e = total_energy(sim.model(), sim.state()) / e0;
      worst = std::max(worst, e);
      lowest = std::min(lowest, e);
      touching += sim.body_contact().pairs().empty() ? 0 : 1;
    }
    EXPECT_GT(touching, 0);
    EXPECT_LE(worst, 1 + 1e-9);
    const std::string name = integrator;
    if (name == "rk4" || name.rfind("arkode", 0) == 0) {
      EXPECT_GT(lowest, 0.99);
    }
  }
}

// The mirrored collision stays mirror-symmetric, positions and velocities to 1e-12, at 1/60 s
// (pairs taken one after another broke it from the third contact step on; vbd's sweeps keep it
// since their colouring is the springs' graph's own, detail/vertex_colouring.hpp).
TEST(BodyContact, AfterStepMirroredCollisionStaysSymmetric) {
  for (const char* integrator : {"implicit_euler", "projective_dynamics", "vbd", "xpbd"}) {
    SCOPED_TRACE(integrator);
    Simulator sim = testing::head_on_cubes(integrator, 1.0 / 60, 0);
    Real asymmetry = 0;
    long touching = 0;
    while (sim.state().t < 0.5) {
      ASSERT_TRUE(sim.step().ok);
      touching += sim.body_contact().pairs().empty() ? 0 : 1;
      asymmetry = std::max(asymmetry, testing::head_on_asymmetry(sim.state()));
    }
    EXPECT_GT(touching, 0);
    EXPECT_LT(asymmetry, 1e-12);
  }
}

// Cubes dropped onto each other onto the floor (3 particles per edge, radius 0.15 m; the second
// 0.4 m above the first, the third, if any, 0.4 m above the second, each shifted sideways by
// `shift`): the stack comes to rest with no particle of one cube closer to one of another than
// the sum of their radii less 1 % (at every step, and at the end), every cube on the one below.
// Returns the top cube's height.
Real stack_rest_height(const std::string& integrator, Real dt, int cubes = 2, Real shift = 0) {
  SCOPED_TRACE(integrator + " at dt = " + std::to_string(dt));
  Model model;
  for (int c = 0; c < cubes; ++c) {
    const CubeSpec cube = testing::small_cube(3, 0.6, Vec3(-0.3 + c * shift, 0.001 + c, -0.3));
    model.add_body("cube" + std::to_string(c),
                   cube.shape().build(cube.material(), "c" + std::to_string(c) + "."));
  }
  Simulator sim = make_sim(model, rest_state(model), integrator, dt);
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
  sim.check_no_overlap();
  const int n = 27;
  const Real r = model.bodies[0].radius;
  EXPECT_EQ(r, 0.15);
  const auto closest = [&](const VecX& x) {
    Real d = 1e9;
    for (int a = 0; a < cubes * n; ++a)
      for (int b = (a / n + 1) * n; b < cubes * n; ++b)
        d = std::min(d, (particle(x, b) - particle(x, a)).norm());
    return d;
  };
  Real closest_ever = 1e9;
  testing::Probe probe(
      [&](const Simulator& sm) { closest_ever = std::min(closest_ever, closest(sm.state().x)); });
  sim.add_observer(probe);
  EXPECT_TRUE(sim.run_until(3.0).ok());
  EXPECT_GT(closest(sim.state().x), 2 * r * 0.99);
  EXPECT_GT(closest_ever, 2 * r * 0.99);
  Real fastest = 0;
  for (int i = 0; i < model.num_particles(); ++i)
    fastest = std::max(fastest, particle(sim.state().v, i).norm());
  EXPECT_LT(fastest, 0.05);
  Real top_y = 0;
  for (int c = 1; c < cubes; ++c) {
    Real low_top = -1e9, high_bottom = 1e9;
    for (int i = (c - 1) * n; i < c * n; ++i) low_top = std::max(low_top, sim.state().x[3 * i + 1]);
    for (int j = c * n; j < (c + 1) * n; ++j)
      high_bottom = std::min(high_bottom, sim.state().x[3 * j + 1]);
    if (shift == 0) {
      EXPECT_NEAR(high_bottom - low_top, 2 * r, 0.01 * r) << "cube " << c;  // resting on it
    } else {
      // Shifted, its particles settle between those below (a vertical gap between 1 and 2 r).
      EXPECT_GT(high_bottom - low_top, r) << "cube " << c;
      EXPECT_LT(high_bottom - low_top, 2 * r * 1.01) << "cube " << c;
    }
  }
  for (int j = (cubes - 1) * n; j < cubes * n; ++j) top_y += sim.state().x[3 * j + 1] / n;
  return top_y;
}

Real stable_dt(const std::string& integrator) {
  return integrator == "explicit_euler" ? 2.5e-4 : 1e-3;
}

TEST_P(BodiesEveryIntegrator, StackComesToRestWithoutOverlap) {
  const Real y = stack_rest_height(GetParam(), stable_dt(GetParam()));
  // Both cubes sag under the weight; the upper one's centre stays within 5 cm of the
  // undeformed stack's 0.6 + 2 r + 0.3.
  EXPECT_NEAR(y, 1.2, 0.05) << GetParam();
}

// implicit_euler at 1/60 and 1/30 s with the pairs inside its solve: two and three cubes, in a
// column and shifted sideways by a third of a lattice spacing, rest on each other without
// overlap.
TEST(BodyContact, ImplicitEulerStackAtLargeSteps) {
  for (const Real dt : {1.0 / 60, 1.0 / 30}) {
    EXPECT_NEAR(stack_rest_height("implicit_euler", dt), 1.2, 0.1);
    EXPECT_NEAR(stack_rest_height("implicit_euler", dt, 3), 2.1, 0.15);
    EXPECT_NEAR(stack_rest_height("implicit_euler", dt, 3, 0.1), 2.0, 0.15);
  }
}

// A checkpoint of implicit_euler carries its contact pairs (friction state): a run restored from
// a snapshot taken while the cubes touch continues bit for bit (with CG, whose arithmetic does not
// depend on the contact blocks the matrix pattern holds; CHOLMOD's ordering does).
TEST(BodyContact, ImplicitEulerRestartsBitForBit) {
  Model model;
  for (int c = 0; c < 2; ++c) {
    const CubeSpec cube = testing::small_cube(3, 0.6, Vec3(-0.3 + 0.1 * c, 0.001 + c, -0.3));
    model.add_body("cube" + std::to_string(c),
                   cube.shape().build(cube.material(), "c" + std::to_string(c) + "."));
  }
  IntegratorOptions o;
  o.implicit.linear_solver = ImplicitLinearSolver::kCg;
  const auto make = [&] {
    Simulator sim(model, rest_state(model), make_integrator("implicit_euler", o),
                  SimulatorOptions{1.0 / 60, 0, {}});
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
    return sim;
  };
  Simulator a = make();
  ASSERT_TRUE(a.run_until(0.8).ok());
  ASSERT_FALSE(a.body_contact().pairs().empty());
  const SimulatorSnapshot snapshot = a.snapshot();
  ASSERT_TRUE(a.run_until(1.2).ok());
  Simulator b = make();
  b.restore(snapshot);
  ASSERT_TRUE(b.run_until(1.2).ok());
  EXPECT_EQ(a.state().x, b.state().x);
  EXPECT_EQ(a.state().v, b.state().v);
}

// The body pairs' part of implicit_euler's saved state: [warm start size, warm start..., -(1 +
// number of values), values...]; returns the index of the first value, or -1 when there is none.
long body_pairs_at(const std::vector<Real>& state) {
  if (state.empty()) return -1;
  const size_t at = 1 + static_cast<size_t>(state[0]);
  return at < state.size() && state[at] < 0 ? static_cast<long>(at + 1) : -1;
}

// A checkpoint whose body pairs no run could have saved (an index beyond int, a mode other than
// 0 or 1, a NaN or negative friction viscosity or stiffness) is an InputError naming the value,
// not undefined behaviour or a silent run.
// Two 27-particle cubes, the second 1 m above the first, and implicit_euler at 1/60 s over a
// floor.
Model stacked_cubes() {
  Model model;
  for (int c = 0; c < 2; ++c) {
    const CubeSpec cube = testing::small_cube(3, 0.6, Vec3(-0.3, 0.001 + c, -0.3));
    model.add_body("cube" + std::to_string(c),
                   cube.shape().build(cube.material(), "c" + std::to_string(c) + "."));
  }
  return model;
}

Simulator make_stack_sim(const Model& model) {
  Simulator sim(model, rest_state(model), make_integrator("implicit_euler", {}),
                SimulatorOptions{1.0 / 60, 0, {}});
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
  return sim;
}

TEST(BodyContact, ImplicitEulerRefusesDamagedContactPairs) {
  const Model model = stacked_cubes();
  const auto make = [&] { return make_stack_sim(model); };
  Simulator a = make();
  ASSERT_TRUE(a.run_until(0.8).ok());
  const SimulatorSnapshot good = a.snapshot();
  const long at = body_pairs_at(good.integrator_state);
  ASSERT_GE(at, 0) << "the cubes should touch at 0.8 s";
  struct Damage {
    int offset;  // i, j, mode, viscosity, kappa
    Real value;
    const char* field;
  };
  for (const Damage& d :
       {Damage{0, -1.0, "body contact pair"}, Damage{1, 1e300, "body contact pair"},
        Damage{2, 2.0, "mode"}, Damage{3, -1.0, "viscosity"}, Damage{3, std::nan(""), "viscosity"},
        Damage{4, 0.0, "stiffness"}, Damage{4, std::nan(""), "stiffness"}}) {
    SimulatorSnapshot bad = good;
    bad.integrator_state[at + d.offset] = d.value;
    Simulator b = make();
    try {
      b.restore(bad);
      ADD_FAILURE() << "accepted " << d.value << " at offset " << d.offset;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr(d.field));
    }
  }
}

// Pairs end with the contact: a run restored from a snapshot with touching pairs, but with the
// upper cube moved 10 m up, finds no candidate in its next step, and its saved state then holds
// no pair (a stale one would count as touching, with its old friction state, when the bodies
// meet again).
TEST(BodyContact, ImplicitEulerForgetsPairsOnceApart) {
  const Model model = stacked_cubes();
  Simulator a = make_stack_sim(model);
  ASSERT_TRUE(a.run_until(0.8).ok());
  SimulatorSnapshot apart = a.snapshot();
  ASSERT_GE(body_pairs_at(apart.integrator_state), 0) << "the cubes should touch at 0.8 s";
  for (int i = 27; i < 54; ++i) apart.state.x[3 * i + 1] += 10;
  apart.state.v.setZero();
  Simulator b = make_stack_sim(model);
  b.restore(apart);
  ASSERT_TRUE(b.run_until(0.8 + 2.0 / 60).ok());
  EXPECT_TRUE(b.body_contact().pairs().empty());
  EXPECT_EQ(body_pairs_at(b.snapshot().integrator_state), -1);
}

// Self-contact never acts between particles that a spring joins: a cube at rest, even squeezed,
// has no self-contact pair; a body folded onto itself has.
TEST(BodyContact, SelfContactExcludesSpringNeighbours) {
  Model model;
  const CubeSpec c = testing::small_cube(4, 0.3, Vec3::Zero());
  model.add_body("cube", c.shape().build(c.material(), "c."));
  BodyContactParams params;
  params.self_contact = true;
  BodyContact contact(params);
  EXPECT_TRUE(contact.active(model));
  State s = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i) particle(s.x, i) *= 0.9;  // squeezed by 10 %
  State before = s;
  contact.resolve(model, before, s, 1e-3);
  EXPECT_TRUE(contact.pairs().empty());
  EXPECT_EQ(s.x, before.x);
  // Without self-contact one body is no contact at all.
  EXPECT_FALSE(BodyContact().active(model));
  // Particle 0 moved onto particle 63 (the far corner): a self-contact pair.
  s = rest_state(model);
  particle(s.x, 0) = particle(s.x, 63) + Vec3(0.01, 0, 0);
  before = s;
  contact.resolve(model, before, s, 1e-3);
  ASSERT_EQ(contact.pairs().size(), 1u);
  EXPECT_EQ(contact.pairs()[0], BroadPhase::Pair(0, 63));
}

TEST(BodyContact, OverlappingBodiesAtTheStartNameBoth) {
  const Model model = two_cubes(-0.05);
  Simulator sim = make_sim(model, rest_state(model), "rk4", 1e-3);
  try {
    sim.check_no_overlap();
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("bodies \"left\" and \"right\" overlap at the start: particle ", 0), 0u) << m;
  }
  // Particles of the two bodies one diameter apart along x are touching, not overlapping.
  const Model touching = two_cubes(0.1);
  Simulator ok = make_sim(touching, rest_state(touching), "rk4", 1e-3);
  EXPECT_NO_THROW(ok.check_no_overlap());
}

TEST(BodyContact, BadParametersNameTheField) {
  BodyContactParams p;
  p.restitution = 2;
  try {
    BodyContact c(p);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "body_contact.restitution = 2 is invalid: a number in [0, 1]");
  }
  p = {};
  p.iterations = 0;
  EXPECT_THROW(BodyContact{p}, InputError);
}

}  // namespace
}  // namespace jelly
