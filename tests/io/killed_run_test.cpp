#include <gtest/gtest.h>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

// A run killed with SIGKILL leaves a file that h5py (and read_recording) can read up to the
// recorder's last flush.
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

}  // namespace
}  // namespace jelly
