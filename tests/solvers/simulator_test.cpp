#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/registry.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

TEST(Registry, SortedNamesAndUnknownName) {
  const auto names = integrator_names();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
  for (const char* expected : {"explicit_euler", "midpoint", "rk4", "symplectic_euler"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
    EXPECT_EQ(make_integrator(expected)->name(), expected);
  }
  try {
    make_integrator("rk5");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("integrator.name = \"rk5\" is invalid: one of \"arkode_dirk\""),
        std::string::npos)
        << e.what();
  }
}

TEST(Simulator, RejectsBadTimeStep) {
  const Model m = build_cube(testing::small_cube(2));
  SimulatorOptions o;
  o.dt = 0;
  try {
    Simulator(m, rest_state(m), make_integrator("rk4"), o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "integrator.dt = 0 is invalid: a finite time step > 0 s");
  }
  o.dt = -1e-3;
  EXPECT_THROW(Simulator(m, rest_state(m), make_integrator("rk4"), o), InputError);
}

// t + dt == t (a far time) would loop forever: refused before the first step.
TEST(Simulator, RefusesStepsAndOutputIntervalsLostToRounding) {
  const Model m = build_cube(testing::small_cube(2));
  State far = rest_state(m);
  far.t = 1e300;
  Simulator sim(m, far, make_integrator("rk4"));
  try {
    sim.run_until(2e300);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "integrator.dt = 0.001 is invalid: a step not lost to rounding at t = "
                 "2.0000000000000001e+300");
  }
  SimulatorOptions o;
  o.output_interval = 1e-300;
  Simulator tiny(m, rest_state(m), make_integrator("rk4"), o);
  EXPECT_THROW(tiny.run_until(1), InputError);
  Simulator fine(m, rest_state(m), make_integrator("rk4"));
  EXPECT_TRUE(fine.run_until(0.01).ok());
}

TEST(Simulator, ObserversAtTheOutputInterval) {
  const Model m = build_cube(testing::small_cube(2));
  Simulator sim = testing::make_sim(m, rest_state(m), "rk4", 0.001, 0.1);
  std::vector<Real> times;
  testing::Probe probe([&](const Simulator& s) { times.push_back(s.state().t); });
  sim.add_observer(probe);
  const RunReport r = sim.run_until(1.0);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.steps, 1000);
  EXPECT_EQ(r.force_evaluations, 4000);
  ASSERT_EQ(times.size(), 11u);
  for (std::size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], 0.1 * k, 1e-9);
  // A second call continues without repeating the frame at its start.
  ASSERT_TRUE(sim.run_until(1.2).ok());
  EXPECT_EQ(times.size(), 13u);
}

TEST(Simulator, RemovedObserverIsNotCalled) {
  const Model m = build_cube(testing::small_cube(2));
  Simulator sim = testing::make_sim(m, rest_state(m), "rk4", 0.001, 0.1);
  int a = 0, b = 0;
  testing::Probe pa([&](const Simulator&) { ++a; });
  testing::Probe pb([&](const Simulator&) { ++b; });
  sim.add_observer(pa);
  sim.add_observer(pb);
  ASSERT_TRUE(sim.run_until(0.2).ok());
  EXPECT_EQ(a, 3);
  EXPECT_EQ(b, 3);
  EXPECT_TRUE(sim.remove_observer(pa));
  EXPECT_FALSE(sim.remove_observer(pa));
  ASSERT_TRUE(sim.run_until(0.4).ok());
  EXPECT_EQ(a, 3);
  EXPECT_EQ(b, 5);
}

// Views of the state (Python's NumPy arrays) rely on its buffers staying where they are.
TEST(Simulator, StateBuffersKeepTheirAddressAndInPlaceChangesAreSeen) {
  const Model m = build_cube(testing::small_cube(3));
  Simulator sim = testing::make_sim(m, rest_state(m), "rk4", 0.001);
  const Real* x = sim.state().x.data();
  const Real* v = sim.state().v.data();
  ASSERT_TRUE(sim.step().ok);
  const SimulatorSnapshot snap = sim.snapshot();
  sim.set_state(rest_state(m));
  sim.restore(snap);
  EXPECT_EQ(sim.state().x.data(), x);
  EXPECT_EQ(sim.state().v.data(), v);
  EXPECT_EQ(sim.state().x, snap.state.x);

  // A velocity set in place moves the jelly in the next step (no gravity: only that motion).
  Model free = m;
  free.gravity.setZero();
  Simulator drift = testing::make_sim(free, rest_state(free), "rk4", 0.001);
  ASSERT_TRUE(drift.step().ok);
  const long steps = drift.total_steps();
  drift.set_state(rest_state(free));
  drift.mutable_state().v.setConstant(1.0);
  ASSERT_TRUE(drift.step().ok);
  EXPECT_EQ(drift.total_steps(), steps + 1);
  EXPECT_NEAR(drift.state().x[0] - rest_state(free).x[0], 0.001, 1e-12);
}

// Explicit Euler far past its stability limit: the guard stops the run and says why.
TEST(Simulator, DivergenceGuardStopsExplicitEuler) {
  const Model m = build_cube(testing::small_cube(4));
  State s = rest_state(m);
  s.v[1] = 1.0;  // a small kick
  Simulator sim = testing::make_sim(m, s, "explicit_euler", 0.05);
  const RunReport r = sim.run_until(10.0);
  EXPECT_EQ(r.status, RunStatus::kDiverged);
  EXPECT_LT(r.t, 10.0);
  EXPECT_GT(r.steps, 0);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_NE(r.brief().find("diverged"), std::string::npos);
}

TEST(Simulator, StableRunIsNotFlagged) {
  const Model m = build_cube(testing::small_cube(4));
  State s = rest_state(m);
  s.v[1] = 1.0;
  Simulator sim = testing::make_sim(m, s, "rk4", 0.001);
  EXPECT_TRUE(sim.run_until(1.0).ok());
}

}  // namespace
}  // namespace jelly
