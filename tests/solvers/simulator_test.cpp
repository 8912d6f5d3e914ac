#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>
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

// A snapshot's step count must leave room to count on (the checkpoint fuzzer's find: a count of
// 2^63 - 1 overflowed at the next step).
TEST(Simulator, RestoreRefusesAStepCountOutOfRange) {
  const Model m = build_cube(testing::small_cube(3));
  Simulator sim = testing::make_sim(m, rest_state(m), "rk4", 0.001);
  SimulatorSnapshot snap = sim.snapshot();
  for (long steps :
       {-1L, SimulatorSnapshot::kMaxTotalSteps + 1, std::numeric_limits<long>::max()}) {
    snap.total_steps = steps;
    try {
      sim.restore(snap);
      ADD_FAILURE() << "restored a snapshot of " << steps << " steps";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr("snapshot.total_steps"));
      EXPECT_THAT(e.what(), ::testing::HasSubstr("[0, 2^53]"));
    }
  }
  snap.total_steps = SimulatorSnapshot::kMaxTotalSteps;
  sim.restore(snap);
  ASSERT_TRUE(sim.step().ok);
  EXPECT_EQ(sim.total_steps(), SimulatorSnapshot::kMaxTotalSteps + 1);
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

namespace jelly {
namespace {

// Counts its frames and finishes; `log` (optional) records its name per frame.
struct Counter final : Observer {
  explicit Counter(std::string counter_name = "", std::vector<std::string>* frame_log = nullptr)
      : name(std::move(counter_name)), log(frame_log) {}
  void on_frame(const Simulator& /*sim*/) override {
    ++frames;
    if (log) log->push_back(name);
  }
  void on_finish(const Simulator& /*sim*/, const RunReport& /*report*/) override { ++finishes; }
  std::string name;
  std::vector<std::string>* log;
  int frames = 0, finishes = 0;
};

Simulator small_sim() {
  const Model m = build_cube(testing::small_cube(2, 1.0, Vec3(0, 1, 0)));
  return testing::make_sim(m, rest_state(m), "rk4", 0.01, 0.01);
}

// An observer destroyed before the next run leaves the simulator: it is not called (under
// AddressSanitizer a call would be a use after free).
TEST(Observers, DestroyedObserverIsNotCalled) {
  Simulator sim = small_sim();
  Counter kept;
  sim.add_observer(kept);
  {
    Counter gone;
    sim.add_observer(gone);
    ASSERT_TRUE(sim.run_until(0.05).ok());
    EXPECT_GT(gone.frames, 0);
    EXPECT_EQ(sim.num_observers(), 2u);
  }
  EXPECT_EQ(sim.num_observers(), 1u);
  ASSERT_TRUE(sim.run_until(0.1).ok());
  EXPECT_EQ(kept.frames, 11);  // t = 0, 0.01, ..., 0.1
  EXPECT_EQ(kept.finishes, 2);
}

// A simulator destroyed first is forgotten by its observers, which may be added elsewhere.
TEST(Observers, DestroyedSimulatorIsForgotten) {
  Counter counter;
  {
    Simulator first = small_sim();
    first.add_observer(counter);
    ASSERT_TRUE(first.run_until(0.02).ok());
  }
  Simulator second = small_sim();
  second.add_observer(counter);
  ASSERT_TRUE(second.run_until(0.02).ok());
  EXPECT_EQ(counter.frames, 6);
}

// remove_observer stops the calls, also from inside a callback, and says whether it removed.
TEST(Observers, RemoveObserver) {
  Simulator sim = small_sim();
  std::vector<std::string> log;
  Counter a("a", &log), b("b", &log);
  sim.add_observer(a);
  sim.add_observer(b);
  sim.add_observer(a);  // once only
  EXPECT_EQ(sim.num_observers(), 2u);
  ASSERT_TRUE(sim.run_until(0.0).ok());
  EXPECT_EQ(log, (std::vector<std::string>{"a", "b"}));
  EXPECT_TRUE(sim.remove_observer(a));
  EXPECT_FALSE(sim.remove_observer(a));
  ASSERT_TRUE(sim.run_until(0.01).ok());
  EXPECT_EQ(log, (std::vector<std::string>{"a", "b", "b"}));

  // An observer that removes the next one (and itself) during its first frame.
  struct Remover final : Observer {
    Simulator* sim = nullptr;
    Observer* victim = nullptr;
    int frames = 0;
    void on_frame(const Simulator& /*s*/) override {
      ++frames;
      sim->remove_observer(*victim);
      sim->remove_observer(*this);
    }
  } remover;
  remover.sim = &sim;
  remover.victim = &b;
  sim.remove_observer(b);
  sim.add_observer(remover);
  sim.add_observer(b);
  const int before = b.frames;
  ASSERT_TRUE(sim.run_until(0.05).ok());
  EXPECT_EQ(remover.frames, 1);
  EXPECT_EQ(b.frames, before);
  EXPECT_EQ(sim.num_observers(), 0u);
}

// An observer destroyed by another observer's callback is skipped in that same pass.
TEST(Observers, DestroyedDuringACallbackIsSkipped) {
  Simulator sim = small_sim();
  auto victim = std::make_unique<Counter>();
  struct Destroyer final : Observer {
    std::unique_ptr<Counter>* victim = nullptr;
    void on_frame(const Simulator& /*s*/) override { victim->reset(); }
  } destroyer;
  destroyer.victim = &victim;
  sim.add_observer(destroyer);
  sim.add_observer(*victim);
  ASSERT_TRUE(sim.run_until(0.03).ok());
  EXPECT_EQ(victim, nullptr);
  EXPECT_EQ(sim.num_observers(), 1u);
}

// Shared ownership: the simulator keeps an observer alive while it is added, and lets it go
// when it is removed or when the simulator is destroyed.
TEST(Observers, SharedOwnership) {
  std::weak_ptr<Counter> watch;
  {
    Simulator sim = small_sim();
    {
      auto counter = std::make_shared<Counter>();
      watch = counter;
      sim.add_observer(counter);
    }
    ASSERT_FALSE(watch.expired());
    ASSERT_TRUE(sim.run_until(0.02).ok());
    EXPECT_EQ(watch.lock()->frames, 3);
    auto other = std::make_shared<Counter>();
    std::weak_ptr<Counter> other_watch = other;
    sim.add_observer(other);
    other.reset();
    EXPECT_TRUE(sim.remove_observer(*other_watch.lock()));
    EXPECT_TRUE(other_watch.expired());
    EXPECT_THROW(sim.add_observer(std::shared_ptr<Observer>()), InputError);
  }
  EXPECT_TRUE(watch.expired());
}

// A moved simulator keeps its observers, which follow it (and leave it when destroyed); a copy
// of an observer is not added anywhere.
TEST(Observers, FollowAMovedSimulatorAndCopiesAreNotAdded) {
  Counter counter;
  Simulator first = small_sim();
  first.add_observer(counter);
  Simulator second = std::move(first);
  ASSERT_TRUE(second.run_until(0.01).ok());
  EXPECT_EQ(counter.frames, 2);
  Counter copy = counter;
  EXPECT_EQ(second.num_observers(), 1u);
  {
    Counter temporary;
    second.add_observer(temporary);
    Simulator third = small_sim();
    third = std::move(second);
    EXPECT_EQ(third.num_observers(), 2u);
    second = std::move(third);
  }
  EXPECT_EQ(second.num_observers(), 1u);
  ASSERT_TRUE(second.run_until(0.02).ok());
  EXPECT_EQ(counter.frames, 3);
  EXPECT_EQ(copy.frames, 2);
}

}  // namespace
}  // namespace jelly

namespace jelly {
namespace {

// A cube squashed to 30 % of its height, and one with a corner pushed through the cube (cells
// inverted): the end of a run reports each, naming the body; an untouched cube is completed
// with its volume ratio 1 and no inverted cell; a cloth is skipped with a note.
TEST(CrushReport, CrushedBodiesEndWithWarnings) {
  const CubeSpec spec = testing::small_cube(5, 1.0, Vec3::Zero());
  Model m;
  m.add_body("squashed", spec.shape().build(spec.material(), "a."));
  m.gravity.setZero();
  State s = rest_state(m);
  for (int i = 0; i < m.num_particles(); ++i) s.x[3 * i + 1] *= 0.3;
  Simulator squashed(m, s, make_integrator("symplectic_euler"));
  RunReport r = squashed.run_until(0);
  EXPECT_EQ(r.status, RunStatus::kCompletedWithWarnings);
  EXPECT_THAT(r.reason, ::testing::HasSubstr("body \"squashed\" is crushed: volume 0.3 of its "
                                             "rest volume, 0 of 64 cells inverted"));
  EXPECT_NEAR(r.statistics.at("volume_ratio.squashed"), 0.3, 1e-12);
  EXPECT_EQ(r.statistics.at("inverted_cells.squashed"), 0);

  // Corner particle (0, 0, 0) moved through to (0.6, 0.6, 0.6): its cell inverted, 1 of 64
  // (1.6 %, under the 5 % limit, and the volume barely changed): completed; a limit of 1 %
  // reports it.
  State corner = rest_state(m);
  particle(corner.x, 0) = Vec3(0.6, 0.6, 0.6);
  Simulator dented(m, corner, make_integrator("symplectic_euler"));
  r = dented.run_until(0);
  EXPECT_EQ(r.status, RunStatus::kCompleted) << r.reason;
  EXPECT_EQ(r.statistics.at("inverted_cells.squashed"), 1);
  SimulatorOptions strict;
  strict.crush.max_inverted_fraction = 0.01;
  Simulator dented_strict(m, corner, make_integrator("symplectic_euler"), strict);
  r = dented_strict.run_until(0);
  EXPECT_EQ(r.status, RunStatus::kCompletedWithWarnings);
  EXPECT_THAT(r.reason, ::testing::HasSubstr("1 of 64 cells inverted"));

  // Untouched, moving freely for a while: not crushed.
  Model free;
  free.add_body("free", spec.shape().build(spec.material(), "f."));
  Simulator fine = testing::make_sim(free, rest_state(free), "xpbd", 1.0 / 60);
  r = fine.run_until(0.5);
  EXPECT_EQ(r.status, RunStatus::kCompleted) << r.reason;
  EXPECT_NEAR(r.statistics.at("volume_ratio.free"), 1, 1e-6);
  EXPECT_EQ(r.statistics.at("inverted_cells.free"), 0);
  EXPECT_TRUE(r.notes.empty());
}

TEST(CrushReport, ClothIsSkippedAndSaysSo) {
  ClothShape cloth;
  cloth.nu = cloth.nv = 4;
  Model m;
  m.add_body("sheet", cloth.build(Material{}, "c."));
  State s = rest_state(m);
  for (int i = 0; i < m.num_particles(); ++i) s.x[3 * i] *= 0.01;  // folded flat: no matter
  Simulator sim(m, s, make_integrator("symplectic_euler"));
  const RunReport r = sim.run_until(0);
  EXPECT_EQ(r.status, RunStatus::kCompleted);
  EXPECT_EQ(r.statistics.count("volume_ratio.sheet"), 0u);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_EQ(r.notes[0], "body \"sheet\" (cloth) has no volume: not checked for crushing");
}

// Tetrahedra oriented either way in the file count as positive at rest; one turned inside out
// counts as inverted.
TEST(CrushReport, InvertedTetrahedraOfATetMesh) {
  TetMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  mesh.tets = {{0, 1, 2, 3}, {1, 3, 2, 4}};
  Model m;
  m.add_body("tets", build_tetmesh(mesh, Pose{}, Material{}, "t."));
  EXPECT_EQ(m.bodies[0].volume.tets.size(), 2u);
  const BodyVolume rest = body_volume(m, m.bodies[0], m.rest_position);
  EXPECT_NEAR(rest.rest, 1.0 / 6 + 1.0 / 3, 1e-12);
  EXPECT_EQ(rest.inverted, 0);
  VecX x = m.rest_position;
  particle(x, 0) = Vec3(0.5, 0.5, 0.5);  // through the face 1, 2, 3
  const BodyVolume flipped = body_volume(m, m.bodies[0], x);
  EXPECT_EQ(flipped.inverted, 1);
  State s = rest_state(m);
  s.x = x;
  Simulator sim(m, s, make_integrator("symplectic_euler"));
  const RunReport r = sim.run_until(0);
  EXPECT_EQ(r.statistics.at("inverted_tets.tets"), 1);
  EXPECT_EQ(r.status, RunStatus::kCompletedWithWarnings);  // 1 of 2 inverted
  EXPECT_THAT(r.reason, ::testing::HasSubstr("body \"tets\" is crushed"));
}

TEST(CrushReport, LimitsAreValidated) {
  SimulatorOptions o;
  o.crush.min_volume_ratio = 1.5;
  try {
    o.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(
        e.what(),
        "crush.min_volume_ratio = 1.5 is invalid: a number in [0, 1] (0: never by volume)");
  }
  o.crush = CrushLimits{};
  o.crush.max_inverted_fraction = -0.1;
  EXPECT_THROW(o.validate(), InputError);
}

}  // namespace
}  // namespace jelly
