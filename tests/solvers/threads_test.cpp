// Every registered integrator gives the same trajectory, bit for bit, on 1, 2 and 3 threads
// (docs/threads.md): fixed partitions, sums in a fixed order.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

class EveryIntegratorThreads : public ::testing::TestWithParam<std::string> {};

// Two bodies: a jelly big enough for every threaded loop to split (about 37,000 springs, 8,232
// unknowns: two chunks of parallel::ordered_sum, six of CG's sums), dropped spinning and squeezed
// onto a 20-degree coulomb slope; and a small cube above the slope, pinned by its top face to a
// path that moves it, in a gusty wind and pushed up by a constant force. The force loop, the pins
// and the external forces all take part.
struct Outcome {
  State state;
  Statistics statistics;
  int contacts = 0;
};

// The jelly alone: 14^3 particles, about 37,000 springs, under gravity.
Model lone_jelly() {
  Model model;
  const int n = 14;
  const CubeSpec spec = testing::small_cube(n, (n - 1) * 4.0 / 9);
  BodySpec jelly;
  jelly.shape = spec.shape();
  jelly.material = spec.material();
  add_body(model, jelly, "bodies[0].");
  model.gravity = spec.gravity;
  return model;
}

Model two_bodies() {
  Model model = lone_jelly();
  BodySpec hanging;
  hanging.name = "hanging";
  CubeShape shape;
  shape.n = 6;
  shape.edge_length = 0.5;
  shape.origin = Vec3(-3, 4, 0);
  hanging.shape = shape;
  hanging.material.particle_mass = 0.2;
  PinSpec top;
  top.select.has_region = true;
  top.select.region = Box3(Vec3(-3.1, 4.45, -0.1), Vec3(-2.4, 4.55, 0.6));
  top.path = Path::oscillation(Vec3(0.02, 0.05, 0), 2.0);
  hanging.pins = {top};
  ExternalForceSpec wind;
  wind.kind = ExternalForceKind::kWind;
  wind.vector = Vec3(4, 0, 1);
  wind.drag = 0.3;
  wind.gust = 0.5;
  wind.gust_frequency = 5;
  ExternalForceSpec push;
  push.vector = Vec3(0, 20, 0);
  hanging.forces = {wind, push};
  add_body(model, hanging, "bodies[1].");
  return model;
}

Outcome run(const Model& model, const std::string& integrator, int threads,
            ContactModel contact = ContactModel::kCoulomb) {
  const Body& jelly = model.bodies.at(0);
  State s = rest_state(model);
  {
    // The jelly lies flat on the slope (corner at the origin, 1 mm above it), squeezed and
    // spinning.
    const Vec3 corner = particle(s.x, jelly.first_particle);
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(-20 * M_PI / 180.0, Vec3::UnitZ()).toRotationMatrix();
    Vec3 centre = Vec3::Zero();
    const int begin = jelly.first_particle, end = begin + jelly.num_particles;
    for (int i = begin; i < end; ++i) {
      particle(s.x, i) = r * (particle(s.x, i) - corner + Vec3(0, 1e-3, 0));
      centre += particle(s.x, i);
    }
    centre /= jelly.num_particles;
    for (int i = begin; i < end; ++i) {
      const Vec3 d = particle(s.x, i) - centre;
      particle(s.x, i) = centre + Vec3(1.02 * d.x(), 0.99 * d.y(), d.z());
      particle(s.v, i) = Vec3(0.5, -1.0, 0.2) + Vec3(0, 0, 1.5).cross(d);
    }
  }
  const auto method = make_integrator(integrator);
  const bool implicit = method->is_implicit(), adaptive = method->is_adaptive();
  SimulatorOptions o;
  // Long enough for contacts and several linear solves; adaptive methods take their own steps
  // (arkode_dirk's Newton iterations, whose Jacobian knows neither the pins nor the wind's drag,
  // are the costly part: two steps).
  o.dt = adaptive ? 1e-3 : implicit ? 1.0 / 100 : 5e-4;
  o.threads = threads;
  Simulator sim(model, s, make_integrator(integrator), o);
  ContactParams params;
  params.model = contact;
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), params)));
  const RunReport report = sim.run_until(adaptive ? 2e-3 : implicit ? 0.05 : 0.02);
  EXPECT_TRUE(report.ok()) << integrator << " on " << threads << " threads: " << report.reason;
  return {sim.state(), report.statistics, sim.contacts().contact_count()};
}

TEST_P(EveryIntegratorThreads, SameTrajectoryOnOneTwoAndThreeThreads) {
  const Model model = two_bodies();
  ASSERT_EQ(model.bodies.size(), 2u);
  ASSERT_EQ(model.pins.size(), 36);
  ASSERT_EQ(model.external_forces.size(), 2u);
  // The threaded band loop takes the forces of both bodies.
  ASSERT_TRUE(SpringBands(model).dense());
  const Outcome one = run(model, GetParam(), 1);
  EXPECT_GT(one.contacts, 0) << "the test should touch the slope";
  // The pinned body moved with its path and the wind (the pins and forces were applied).
  const Body& hanging = model.bodies.at(1);
  EXPECT_GT((one.state.x - rest_state(model).x)
                .segment(3 * hanging.first_particle, 3 * hanging.num_particles)
                .cwiseAbs()
                .maxCoeff(),
            1e-4);
  for (int threads : {2, 3}) {
    const Outcome other = run(model, GetParam(), threads);
    EXPECT_TRUE(other.state.x == one.state.x) << threads << " threads";
    EXPECT_TRUE(other.state.v == one.state.v) << threads << " threads";
    EXPECT_EQ(other.contacts, one.contacts);
    for (const char* counter : {"cg_iterations", "linear_solves", "newton_iterations"}) {
      if (one.statistics.count(counter) > 0) {
        EXPECT_EQ(other.statistics.at(counter), one.statistics.at(counter)) << counter;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryIntegratorThreads, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// A lone jelly with gravity and springs alone: the force loop divides by the masses as it writes
// its sums (Dynamics' springs-only evaluation), on every split of the particles the same bits.
TEST(Threads, SpringsOnlyJellySameTrajectoryOnOneTwoAndThreeThreads) {
  const Model model = lone_jelly();
  ASSERT_TRUE(SpringBands(model).dense());
  for (const char* integrator : {"explicit_euler", "symplectic_euler", "midpoint", "rk4"}) {
    const Outcome one = run(model, integrator, 1);
    EXPECT_GT(one.contacts, 0) << integrator;
    for (int threads : {2, 3}) {
      const Outcome other = run(model, integrator, threads);
      EXPECT_TRUE(other.state.x == one.state.x) << integrator << ", " << threads << " threads";
      EXPECT_TRUE(other.state.v == one.state.v) << integrator << ", " << threads << " threads";
    }
  }
}

// The same on the seed contact model: the force loop's threads add the seed contact forces to
// their own particles before dividing by the masses.
TEST(Threads, SeedContactJellySameTrajectoryOnOneTwoAndThreeThreads) {
  const Model model = lone_jelly();
  for (const char* integrator : {"explicit_euler", "rk4"}) {
    const Outcome one = run(model, integrator, 1, ContactModel::kSeed);
    EXPECT_GT(one.contacts, 0) << integrator;
    for (int threads : {2, 3}) {
      const Outcome other = run(model, integrator, threads, ContactModel::kSeed);
      EXPECT_TRUE(other.state.x == one.state.x) << integrator << ", " << threads << " threads";
      EXPECT_TRUE(other.state.v == one.state.v) << integrator << ", " << threads << " threads";
    }
  }
}

// Dynamics' springs-only evaluation (accelerations from the force loop, then the pins' paths)
// gives the bits of forces() divided by the masses, with pinned particles on their paths.
TEST(Threads, SpringsOnlyAccelerationsAreTheForcesOverTheMasses) {
  Model model = lone_jelly();
  model.pins.add_fixed(0, particle(rest_state(model).x, 0));
  model.pins.add_fixed(5, particle(rest_state(model).x, 5));
  const SpringBands bands(model);
  ContactSolver contacts;
  State s = rest_state(model);
  for (int i = 0; i < s.x.size(); ++i) {
    s.x[i] += 1e-3 * std::sin(0.37 * i);
    s.v[i] = 0.1 * std::cos(0.11 * i);
  }
  for (int threads : {1, 2, 3}) {
    const Dynamics dynamics(model, contacts, nullptr, &bands, nullptr, threads);
    VecX a(model.num_dofs()), f(model.num_dofs());
    dynamics.acceleration(0.1, s.x, s.v, a);
    dynamics.forces(0.1, s.x, s.v, f);
    for (int i = 0; i < model.num_particles(); ++i) {
      const Real inv = 1.0 / model.mass[i];
      for (int d = 0; d < 3; ++d) f[3 * i + d] *= inv;
    }
    model.pins.apply_acceleration(0.1, f);
    EXPECT_TRUE(a == f) << threads << " threads";
    EXPECT_EQ(Vec3(particle(a, 5)), Vec3::Zero());
    EXPECT_EQ(dynamics.force_evaluations(), 2);
  }
}

// With seed contacts (particles in every thread's range, some pushed into the surface by their
// forces, some not), the force loop's evaluation gives the bits of forces() over the masses.
TEST(Threads, SeedContactAccelerationsAreTheForcesOverTheMasses) {
  const Model model = lone_jelly();
  const SpringBands bands(model);
  State s = rest_state(model);
  for (int i = 0; i < s.x.size(); ++i) {
    s.x[i] += 1e-3 * std::sin(0.37 * i);
    s.v[i] = 0.1 * std::cos(0.11 * i);
  }
  std::vector<ContactSolver::SeedContact> seed;
  for (int i = 0; i < model.num_particles(); i += 97)
    seed.push_back({i, Vec3(std::sin(0.1 * i), 1, 0.2).normalized(), 0.5});
  ContactSolver contacts;
  contacts.restore(seed, static_cast<int>(seed.size()));
  ASSERT_GT(seed.size(), 20u);
  for (int threads : {1, 2, 3}) {
    const Dynamics dynamics(model, contacts, nullptr, &bands, nullptr, threads);
    VecX a(model.num_dofs()), f(model.num_dofs()), springs(model.num_dofs());
    dynamics.acceleration(0.1, s.x, s.v, a);
    dynamics.forces(0.1, s.x, s.v, f);
    bands.compute_forces(model, s.x, s.v, springs, threads);
    EXPECT_FALSE(f == springs) << "the contact forces should change some forces";
    divide_by_masses(model, f);
    EXPECT_TRUE(a == f) << threads << " threads";
  }
}

// The option: 0 = all cores; negative is an input error.
TEST(Threads, OptionIsValidated) {
  const Model model = build_cube(testing::small_cube(3));
  SimulatorOptions o;
  o.threads = -1;
  EXPECT_THROW(Simulator(model, rest_state(model), make_integrator("rk4"), o), InputError);
  o.threads = 0;
  EXPECT_NO_THROW(Simulator(model, rest_state(model), make_integrator("rk4"), o));
}

}  // namespace
}  // namespace jelly
