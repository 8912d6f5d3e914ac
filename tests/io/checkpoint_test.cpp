#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>

#include "io/io_support.hpp"

namespace jelly {

// Names the contact model in test output (GoogleTest finds it in the type's namespace).
void PrintTo(ContactModel model, std::ostream* out) { *out << contact_model_name(model); }

namespace {

using testing::TempDir;

struct Trajectory {
  std::vector<Real> t;
  std::vector<VecX> x, v;
};

// Attaches an observer that appends each frame at or after t_from to `out`.
auto collect(Trajectory& out, Real t_from) {
  return testing::Probe([&out, t_from](const Simulator& s) {
    if (s.state().t < t_from - 1e-12) return;
    out.t.push_back(s.state().t);
    out.x.push_back(s.state().x);
    out.v.push_back(s.state().v);
  });
}

void expect_identical(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.t.size(), b.t.size());
  ASSERT_GT(a.t.size(), 10u);
  for (size_t f = 0; f < a.t.size(); ++f) {
    ASSERT_EQ(a.t[f], b.t[f]) << "frame " << f;
    ASSERT_TRUE(a.x[f] == b.x[f]) << "positions differ at t = " << a.t[f];
    ASSERT_TRUE(a.v[f] == b.v[f]) << "velocities differ at t = " << a.t[f];
  }
}

// The frames of `whole` from index `cut` on equal those of `resumed`, bit for bit.
void expect_tail_identical(const Trajectory& whole, size_t cut, const Trajectory& resumed) {
  Trajectory tail;
  tail.t.assign(whole.t.begin() + static_cast<std::ptrdiff_t>(cut), whole.t.end());
  tail.x.assign(whole.x.begin() + static_cast<std::ptrdiff_t>(cut), whole.x.end());
  tail.v.assign(whole.v.begin() + static_cast<std::ptrdiff_t>(cut), whole.v.end());
  expect_identical(tail, resumed);
}

constexpr Real kEnd = 1.0;

class Restart : public ::testing::TestWithParam<ContactModel> {};
INSTANTIATE_TEST_SUITE_P(Contact, Restart,
                         ::testing::Values(ContactModel::kCoulomb, ContactModel::kSeed,
                                           ContactModel::kSeedFramework),
                         [](const auto& p) { return std::string(contact_model_name(p.param)); });

// A run stopped half way (its recorder writes the final checkpoint) and continued from the file
// in a fresh simulator reproduces the uninterrupted run bit for bit. With the seed model the cut
// is put at a frame where seed contacts are active, so that their restoration is exercised.
TEST_P(Restart, FromFinalCheckpointIsBitForBit) {
  TempDir dir;
  Trajectory whole, resumed;
  std::vector<size_t> seed_contacts;
  {
    Simulator sim = testing::slope_sim(GetParam());
    auto probe = collect(whole, 0);
    testing::Probe contacts(
        [&](const Simulator& s) { seed_contacts.push_back(s.contacts().seed_contacts().size()); });
    sim.add_observer(probe);
    sim.add_observer(contacts);
    ASSERT_TRUE(sim.run_until(kEnd).ok());
  }
  size_t cut = whole.t.size() / 2;
  if (GetParam() == ContactModel::kSeed) {
    while (cut < whole.t.size() && seed_contacts[cut] == 0) ++cut;
    ASSERT_LT(cut + 10, whole.t.size()) << "no frame with seed contacts in the second half";
  }
  const std::string path = dir.file("half.h5");
  {
    Simulator sim = testing::slope_sim(GetParam());
    H5Recorder recorder(path, sim);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(whole.t[cut]).ok());
  }
  const Checkpoint cp = read_checkpoint(path);
  EXPECT_EQ(cp.state.t, whole.t[cut]);
  EXPECT_EQ(cp.integrator, "rk4");
  EXPECT_EQ(cp.seed_contacts.size(), seed_contacts[cut]);
  Simulator sim = testing::slope_sim(GetParam());
  restore(sim, cp);
  EXPECT_EQ(sim.total_steps(), cp.total_steps);
  auto probe = collect(resumed, 0);
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(kEnd).ok());
  expect_tail_identical(whole, cut, resumed);
}

// The checkpoint written at a mid-run flush (copied when the recorder had just flushed) restarts
// the run bit for bit too: the next output time it stores is the one after that frame.
TEST_P(Restart, FromMidRunFlushIsBitForBit) {
  TempDir dir;
  const std::string path = dir.file("run.h5"), copy = dir.file("copy.h5");
  Trajectory whole, resumed;
  {
    Simulator sim = testing::slope_sim(GetParam());
    RecorderOptions options;
    options.flush_every_frames = 5;
    options.background_writer = false;  // flushed when on_frame returns
    H5Recorder recorder(path, sim, options);
    int frames = 0;
    testing::Probe copier([&](const Simulator&) {
      if (++frames == 25) std::filesystem::copy_file(path, copy);
    });
    auto probe = collect(whole, 0);
    sim.add_observer(recorder);
    sim.add_observer(copier);
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(kEnd).ok());
  }
  const Checkpoint cp = read_checkpoint(copy);
  ASSERT_EQ(cp.state.t, whole.t[24]);
  Simulator sim = testing::slope_sim(GetParam());
  restore(sim, cp);
  auto probe = collect(resumed, 0);
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(kEnd).ok());
  expect_tail_identical(whole, 24, resumed);
}

// implicit_euler keeps a CG warm start and its contact set (sticking or sliding, with its
// friction) between steps; the checkpoint stores them, so a restart on the slope with contact
// inside the solve continues bit for bit too (direct CHOLMOD at this size, as `auto` picks).
TEST(Restart, ImplicitEulerWithContactIsBitForBit) {
  TempDir dir;
  const std::string path = dir.file("implicit.h5");
  const auto slope = [] { return testing::slope_sim(ContactModel::kCoulomb, 3, "implicit_euler"); };
  Trajectory whole, resumed;
  {
    Simulator sim = slope();
    auto probe = collect(whole, 0);
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(kEnd).ok());
  }
  const size_t cut = whole.t.size() / 2;
  {
    Simulator sim = slope();
    H5Recorder recorder(path, sim);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(whole.t[cut]).ok());
    ASSERT_GT(sim.contacts().contact_count(), 0);  // the cut falls in contact
  }
  const Checkpoint cp = read_checkpoint(path);
  EXPECT_GT(cp.integrator_state.size(), 1u);
  Simulator sim = slope();
  restore(sim, cp);
  auto probe = collect(resumed, 0);
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(kEnd).ok());
  expect_tail_identical(whole, cut, resumed);
}

TEST(Restart, MismatchedSimulatorIsAnInputError) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  {
    Simulator sim = testing::slope_sim();
    H5Recorder recorder(path, sim);
    sim.add_observer(recorder);
    sim.run_until(0.1);
  }
  const Checkpoint cp = read_checkpoint(path);
  Simulator other = testing::slope_sim(ContactModel::kCoulomb, 3, "midpoint");
  EXPECT_THROW(restore(other, cp), InputError);
  Simulator bigger = testing::slope_sim(ContactModel::kCoulomb, 4);
  EXPECT_THROW(restore(bigger, cp), InputError);
  EXPECT_THROW(read_checkpoint(dir.file("missing.h5")), InputError);
}

}  // namespace
}  // namespace jelly

namespace jelly {
namespace {

// Live edits (a spring type's ks, gravity, a pin driven from code) go into the checkpoint: a
// simulator built from the original scene and restored from the file continues the edited run
// exactly.
TEST(Restart, AfterLiveEditsTheCheckpointContinuesTheEditedRun) {
  TempDir dir;
  const std::string path = dir.file("edited.h5");
  Scene scene =
      load_scene(std::string(JELLY_SOURCE_DIR) + "/scenes/drop_coulomb.json", {"cube.n=4"});
  scene.integrator.name = "implicit_euler";
  scene.integrator.dt = 0.01;
  Simulator sim = make_simulator(scene);
  {
    H5Recorder recorder(path, sim);
    sim.add_observer(recorder);
    sim.run_until(0.3);
    sim.set_spring_coefficients(0, SpringType::kStructural, {300, 4});
    sim.set_gravity(Vec3(1, -9.8, 0));
    sim.set_pin(63, particle(sim.state().x, 63), Path());
    sim.set_pin_target(63, particle(sim.state().x, 63), Vec3(0, 0.5, 0));
    sim.run_until(0.6);
  }
  const Checkpoint cp = read_checkpoint(path);
  ASSERT_TRUE(cp.model_values.has_value());
  Simulator resumed = make_simulator(scene);  // the scene as the file gave it, unedited
  restore(resumed, cp);
  EXPECT_EQ(resumed.model().gravity, Vec3(1, -9.8, 0));
  EXPECT_EQ(resumed.model().pins.size(), 1);
  sim.run_until(1.0);
  resumed.run_until(1.0);
  EXPECT_EQ(sim.state().x, resumed.state().x);
  EXPECT_EQ(sim.state().v, resumed.state().v);
  // Without the edits the restart would have gone elsewhere.
  Simulator unedited = make_simulator(scene);
  unedited.restore([&] {
    SimulatorSnapshot s = cp.snapshot();
    s.model_values.reset();
    return s;
  }());
  unedited.run_until(1.0);
  EXPECT_NE(unedited.state().x, resumed.state().x);
}

}  // namespace
}  // namespace jelly
