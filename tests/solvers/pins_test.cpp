// Pinned particles and external forces: pins hold exactly for every integrator (implicit_euler
// at a game's step included), driven pins follow their path, a pendulum on a pin keeps its
// analytic period, a chain hanging from a pin settles where a direct solve of its springs puts
// it, two free bodies conserve momentum, and wind drags a free particle to the air's speed.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include <jelly/core/measures.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::make_sim;

class PinsEveryIntegrator : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Registry, PinsEveryIntegrator, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// The step each method is run at: a game's 1/60 s for implicit_euler, 1 ms for the others.
Real step_for(const std::string& integrator) {
  return integrator == "implicit_euler" ? 1.0 / 60 : 1e-3;
}

// A 6 x 6 cloth pinned at two corners, and a small cube pinned at its top face and driven up
// and down, falling onto a floor.
Model pinned_model() {
  Model model;
  ClothShape cloth;
  cloth.nu = 6;
  cloth.nv = 6;
  cloth.pose.position = Vec3(0, 1.5, 0);
  BodySpec sheet;
  sheet.name = "sheet";
  sheet.shape = cloth;
  sheet.material.particle_mass = 0.05;
  sheet.material.springs.fill({200, 1});  // stable at 1 ms for the explicit methods
  sheet.pins = {PinSpec{{{}, false, {}, "corner_00"}, Path()},
                PinSpec{{{}, false, {}, "corner_10"}, Path()}};
  add_body(model, sheet, "bodies[0].");
  BodySpec cube;
  cube.name = "jelly";
  CubeShape shape;
  shape.n = 3;
  shape.edge_length = 0.4;
  shape.origin = Vec3(1, 0.2, 0);
  cube.shape = shape;
  cube.material.particle_mass = 0.1;
  cube.material.springs.fill({500, 2});
  PinSpec top;
  top.select.has_region = true;
  top.select.region = Box3(Vec3(0.9, 0.55, -0.1), Vec3(1.5, 0.65, 0.5));
  top.path = Path::oscillation(Vec3(0, 0.1, 0), 1.0);
  cube.pins = {top};
  add_body(model, cube, "bodies[1].");
  return model;
}

TEST_P(PinsEveryIntegrator, PinsHoldExactlyAndDrivenPinsFollowTheirPath) {
  const Model model = pinned_model();
  ASSERT_EQ(model.pins.size(), 2 + 9);
  Simulator sim = make_sim(model, rest_state(model), GetParam(), step_for(GetParam()));
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
  for (int k = 0; k < 60; ++k) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << r.message;
    const State& s = sim.state();
    for (int p = 0; p < model.pins.size(); ++p) {
      const int i = model.pins.particles[p];
      const PathSample path = model.pins.sample(p, s.t);
      // To the last bit: the anchor plus the path's offset.
      ASSERT_EQ(Vec3(particle(s.x, i)), Vec3(model.pins.anchors[p] + path.offset))
          << "pin " << p << " at t = " << s.t;
      ASSERT_EQ(Vec3(particle(s.v, i)), path.velocity) << "pin " << p << " at t = " << s.t;
    }
  }
  // The free particles moved (the cloth swings, the cube is shaken), and nothing blew up.
  const State& s = sim.state();
  EXPECT_TRUE(s.x.allFinite() && s.v.allFinite());
  EXPECT_GT((particle(s.x, 35) - particle(model.rest_position, 35)).norm(), 1e-3);
}

// A particle on a spring from a pinned one: a pendulum of length L (stiff spring, no damping)
// swinging by a small angle has period 2 pi sqrt(L / g).
TEST(Pins, PendulumKeepsItsAnalyticPeriod) {
  const Real length = 1.0, g = 9.8, angle = 0.05;
  Model model;
  model.mass = VecX::Constant(2, 1.0);
  model.rest_position = VecX::Zero(6);
  model.rest_position.segment<3>(3) = Vec3(length * std::sin(angle), -length * std::cos(angle), 0);
  model.springs.add(0, 1, length, {1e6, 0}, SpringType::kStructural);
  model.pins.add_fixed(0, Vec3::Zero());
  Simulator sim = make_sim(model, rest_state(model), "rk4", 1e-4);
  // Time of the third crossing of x = 0 from positive to negative... (2.5 periods after start
  // at the extreme: crossings at T/4, 3T/4, 5T/4).
  Real last_x = sim.state().x[3], crossing = -1;
  int crossings = 0;
  while (sim.state().t < 3.0 && crossings < 3) {
    ASSERT_TRUE(sim.step().ok);
    const Real x = sim.state().x[3];
    if ((x < 0) != (last_x < 0)) {
      ++crossings;
      crossing = sim.state().t - 1e-4 * x / (x - last_x);
    }
    last_x = x;
  }
  ASSERT_EQ(crossings, 3);
  const Real period = crossing / 1.25;
  const Real exact = 2 * M_PI * std::sqrt(length / g) * (1 + angle * angle / 16);
  EXPECT_NEAR(period, exact, 1e-3 * exact);
}

// A chain of n particles hanging from a pin at the top comes to rest where each spring carries
// the weight below it: spring i (from the top) stretches by (n - 1 - i) m g / ks.
TEST(Pins, HangingChainSettlesAtTheStaticEquilibrium) {
  const int n = 8;
  const Real m = 0.2, ks = 400, l0 = 0.1, g = 9.8;
  Model model;
  model.mass = VecX::Constant(n, m);
  model.rest_position = VecX::Zero(3 * n);
  for (int i = 0; i < n; ++i) model.rest_position[3 * i + 1] = -l0 * i;
  for (int i = 0; i + 1 < n; ++i) model.springs.add(i, i + 1, l0, {ks, 5}, SpringType::kStructural);
  model.pins.add_fixed(0, Vec3::Zero());
  for (const std::string integrator : {"implicit_euler", "rk4"}) {
    SCOPED_TRACE(integrator);
    Simulator sim =
        make_sim(model, rest_state(model), integrator, integrator == "rk4" ? 1e-3 : 0.01);
    ASSERT_TRUE(sim.run_until(20.0).ok());
    Real y = 0;
    for (int i = 1; i < n; ++i) {
      y -= l0 + (n - i) * m * g / ks;
      EXPECT_NEAR(sim.state().x[3 * i + 1], y, 1e-6) << "particle " << i;
      EXPECT_NEAR(sim.state().x[3 * i], 0, 1e-12);
    }
  }
}

// Two free cubes without gravity, thrown at different speeds and spinning: linear and angular
// momentum of the whole model stay constant (symplectic Euler conserves both exactly).
TEST(Bodies, TwoFreeBodiesConserveMomentum) {
  Model model;
  CubeSpec a = testing::small_cube(3, 0.5, Vec3(-2, 0, 0));
  CubeSpec b = testing::small_cube(4, 0.6, Vec3(2, 0, 0));
  b.springs[0] = {3000, 10};
  model.add_body("a", a.shape().build(a.material(), "a."));
  model.add_body("b", b.shape().build(b.material(), "b."));
  model.gravity.setZero();
  State s = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i) {
    const Vec3 x = particle(s.x, i);
    particle(s.v, i) = (i < 27 ? Vec3(1, 0, 0) : Vec3(-0.5, 0.2, 0)) + Vec3(0, 0, 0.3 * x.y());
  }
  Simulator sim = make_sim(model, s, "symplectic_euler", 1e-3);
  const Vec3 p0 = linear_momentum(model, s.v), l0 = angular_momentum(model, s.x, s.v);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  EXPECT_LT((linear_momentum(model, sim.state().v) - p0).norm(), 1e-9 * p0.norm());
  EXPECT_LT((angular_momentum(model, sim.state().x, sim.state().v) - l0).norm(), 1e-9 * l0.norm());
}

// Wind: drag (w - v) on a free particle; without gravity its speed tends to the air's,
// v(t) = w (1 - exp(-drag t / m)).
TEST(ExternalForces, WindDragsAParticleToTheAirSpeed) {
  for (const std::string integrator : {"rk4", "implicit_euler"}) {
    SCOPED_TRACE(integrator);
    Model model;
    model.mass = VecX::Constant(1, 2.0);
    model.rest_position = VecX::Zero(3);
    model.gravity.setZero();
    ExternalForce wind;
    wind.kind = ExternalForceKind::kWind;
    wind.particles = {0};
    wind.vector = Vec3(3, 0, 0);
    wind.drag = 1.0;
    model.external_forces = {wind};
    const Real h = integrator == "rk4" ? 1e-3 : 1e-4;
    Simulator sim = make_sim(model, rest_state(model), integrator, h);
    ASSERT_TRUE(sim.run_until(2.0).ok());
    const Real t = sim.state().t;
    EXPECT_NEAR(sim.state().v[0], 3 * (1 - std::exp(-t / 2.0)), integrator == "rk4" ? 1e-9 : 1e-4);
  }
}

// A constant force spread over a body by mass accelerates it by F / M.
TEST(ExternalForces, ConstantForceAcceleratesTheBody) {
  Model model = build_cube(testing::small_cube(3, 0.5));
  model.gravity.setZero();
  ExternalForce push;
  push.kind = ExternalForceKind::kConstant;
  for (int i = 0; i < model.num_particles(); ++i) push.particles.push_back(i);
  push.vector = Vec3(0, 0, 27);  // N, on 27 kg
  model.external_forces = {push};
  Simulator sim = make_sim(model, rest_state(model), "rk4", 1e-3);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  for (int i = 0; i < model.num_particles(); ++i) {
    EXPECT_NEAR(sim.state().v[3 * i + 2], 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace jelly
