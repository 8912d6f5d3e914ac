#include <gtest/gtest.h>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <jelly/io/checkpoint.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

std::string h5py_frame_count(const std::string& path) {
  return "/usr/bin/python3 -c \"import sys, h5py; f = h5py.File(sys.argv[1], 'r'); "
         "n = f['particles/jelly/position/value'].shape[0]; "
         "t = f['particles/jelly/position/time'][:]; e = f['observables/total_energy/value'][:]; "
         "print('h5py read', n, 'frames'); sys.exit(0 if n >= 1 and len(t) == n and len(e) == n "
         "else 1)\" " +
         path;
}

// A run killed with SIGKILL at a random moment (here while its writer thread flushes after
// every frame, the worst case) leaves a file that h5py and read_recording can read.
TEST(KilledRun, FileStaysReadable) {
  if (!testing::python_has("h5py")) GTEST_SKIP() << "/usr/bin/python3 with h5py not available";
  testing::TempDir dir;
  const std::string path = dir.file("killed.h5");
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(ready[0]);
    Simulator sim = testing::slope_sim(ContactModel::kCoulomb, 4, "rk4", 0.01);
    RecorderOptions options;
    options.flush_every_frames = 1;
    H5Recorder recorder(path, sim, options);
    int frames = 0;
    testing::Probe signal_parent([&](const Simulator&) {
      if (++frames == 20) {
        const char byte = 1;
        (void)!write(ready[1], &byte, 1);
      }
    });
    sim.add_observer(recorder);
    sim.add_observer(signal_parent);
    sim.run_until(1e6);  // runs until killed
    _exit(0);
  }
  close(ready[1]);
  pollfd fd{ready[0], POLLIN, 0};
  const bool signalled = poll(&fd, 1, 60000) == 1;
  char byte = 0;
  if (signalled) (void)!read(ready[0], &byte, 1);
  usleep(50000);  // the writer is busy mid-frame when the kill lands
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  close(ready[0]);
  ASSERT_TRUE(signalled) << "the child never reached 20 frames";
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

  const std::string check =
      "/usr/bin/python3 -c \"import sys, h5py; f = h5py.File(sys.argv[1], 'r'); "
      "n = f['particles/jelly/position/value'].shape[0]; t = "
      "f['particles/jelly/position/time'][:]; "
      "print('h5py read', n, 'frames'); sys.exit(0 if n >= 1 and len(t) >= 1 else 1)\" " +
      path;
  EXPECT_EQ(std::system(check.c_str()), 0);
  const Recording r = read_recording(path);
  EXPECT_GE(r.frames(), 1);
  EXPECT_EQ(r.attributes.at("run_status"), "running");
}

// Killed after a flush (the child stops in its 20th frame, after the recorder has written it), the
// file holds exactly the flushed frames, and its checkpoint continues the run bit for bit.
TEST(KilledRun, AfterAFlushHoldsEveryFlushedFrameAndRestarts) {
  if (!testing::python_has("h5py")) GTEST_SKIP() << "/usr/bin/python3 with h5py not available";
  testing::TempDir dir;
  const std::string path = dir.file("killed.h5");
  const auto make_sim = [] { return testing::slope_sim(ContactModel::kSeed, 3, "rk4", 0.02); };
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(ready[0]);
    Simulator sim = make_sim();
    RecorderOptions options;
    options.flush_every_frames = 1;
    options.background_writer = false;  // the frame is flushed when on_frame returns
    H5Recorder recorder(path, sim, options);
    int frames = 0;
    testing::Probe stop([&](const Simulator&) {
      if (++frames < 20) return;
      const char byte = 1;
      (void)!write(ready[1], &byte, 1);
      for (;;) pause();  // wait here for the SIGKILL
    });
    sim.add_observer(recorder);
    sim.add_observer(stop);
    sim.run_until(1e6);
    _exit(0);
  }
  close(ready[1]);
  pollfd fd{ready[0], POLLIN, 0};
  const bool signalled = poll(&fd, 1, 60000) == 1;
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  close(ready[0]);
  ASSERT_TRUE(signalled) << "the child never reached 20 frames";

  EXPECT_EQ(std::system(h5py_frame_count(path).c_str()), 0);
  const Recording r = read_recording(path);
  ASSERT_EQ(r.frames(), 20);

  // The same run, uninterrupted, continues the killed one's checkpoint exactly.
  std::vector<VecX> expected;
  Simulator whole = make_sim();
  testing::Probe collect([&](const Simulator& s) { expected.push_back(s.state().x); });
  whole.add_observer(collect);
  whole.run_until(0.6);
  EXPECT_EQ(r.position[19], expected[19]);
  const Checkpoint cp = read_checkpoint(path);
  EXPECT_EQ(cp.state.t, r.time[19]);
  Simulator resumed = make_sim();
  restore(resumed, cp);
  std::vector<VecX> after;
  testing::Probe collect_after([&](const Simulator& s) { after.push_back(s.state().x); });
  resumed.add_observer(collect_after);
  resumed.run_until(0.6);
  ASSERT_EQ(after.size(), expected.size() - 19);
  for (size_t f = 0; f < after.size(); ++f) EXPECT_TRUE(after[f] == expected[19 + f]) << f;
}

}  // namespace
}  // namespace jelly
