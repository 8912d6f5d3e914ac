// Every registered integrator gives the same trajectory, bit for bit, on 1, 2 and 3 threads
// (docs/threads.md): fixed partitions, sums in a fixed order.
#include <gtest/gtest.h>

#include <jelly/core/cube.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

class EveryIntegratorThreads : public ::testing::TestWithParam<std::string> {};

// A jelly big enough for every threaded loop to split (about 37,000 springs, 8,232 unknowns:
// two sum chunks), dropped spinning and squeezed onto a 20-degree coulomb slope.
struct Outcome {
  State state;
  Statistics statistics;
  int contacts = 0;
};

Outcome run(const std::string& integrator, int threads) {
  const int n = 14;
  const Model model = build_cube(testing::small_cube(n, (n - 1) * 4.0 / 9));
  State s = testing::cube_on_slope(model, 20);
  const Vec3 centre = center_of_mass(model, s);
  for (int i = 0; i < model.num_particles(); ++i) {
    const Vec3 r = particle(s.x, i) - centre;
    particle(s.x, i) = centre + Vec3(1.02 * r.x(), 0.97 * r.y(), r.z());
    particle(s.v, i) = Vec3(0.5, -1.0, 0.2) + Vec3(0, 0, 1.5).cross(r);
  }
  const auto method = make_integrator(integrator);
  const bool implicit = method->is_implicit(), adaptive = method->is_adaptive();
  SimulatorOptions o;
  // Long enough for contacts and several linear solves; adaptive methods take their own steps.
  o.dt = adaptive ? 1e-3 : implicit ? 1.0 / 100 : 5e-4;
  o.threads = threads;
  Simulator sim(model, s, make_integrator(integrator), o);
  ContactParams coulomb;
  coulomb.model = ContactModel::kCoulomb;
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), coulomb)));
  const RunReport report = sim.run_until(adaptive ? 5e-3 : implicit ? 0.05 : 0.02);
  EXPECT_TRUE(report.ok()) << integrator << " on " << threads << " threads: " << report.reason;
  return {sim.state(), report.statistics, sim.contacts().contact_count()};
}

TEST_P(EveryIntegratorThreads, SameTrajectoryOnOneTwoAndThreeThreads) {
  const Outcome one = run(GetParam(), 1);
  EXPECT_GT(one.contacts, 0) << "the test should touch the slope";
  for (int threads : {2, 3}) {
    const Outcome other = run(GetParam(), threads);
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
