// A recorder never destroys a file it did not create unless told to: an existing recording or
// sidecar is an InputError, or with `overwrite` it is replaced only once the new recording is
// complete. Problems with the sidecar are found when the recorder is created, not after the run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;
namespace fs = std::filesystem;

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string creation_error(const std::string& path, RecorderOptions options = {}) {
  Simulator sim = testing::slope_sim();
  try {
    H5Recorder recorder(path, sim, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Files in `dir` whose name contains ".partial-".
int partial_files(const std::string& dir) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().find(".partial-") != std::string::npos) ++count;
  }
  return count;
}

TEST(OutputFiles, AnExistingRecordingOrSidecarIsRefused) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  write(path, "precious");
  EXPECT_THAT(creation_error(path),
              HasSubstr("cannot write the recording '" + path + "': the file exists"));
  EXPECT_EQ(contents(path), "precious");

  const std::string other = dir.file("other.h5");
  write(dir.file("other.xdmf"), "precious too");
  EXPECT_THAT(creation_error(other), HasSubstr("cannot write the XDMF sidecar '" +
                                               dir.file("other.xdmf") + "': the file exists"));
  EXPECT_FALSE(fs::exists(other));
  EXPECT_EQ(contents(dir.file("other.xdmf")), "precious too");
}

TEST(OutputFiles, ARecordingNamedLikeItsSidecarIsRefused) {
  TempDir dir;
  EXPECT_THAT(creation_error(dir.file("run.xdmf")),
              HasSubstr("its XDMF sidecar would have the same name"));
  EXPECT_FALSE(fs::exists(dir.file("run.xdmf")));
}

TEST(OutputFiles, AnUnwritableSidecarIsFoundBeforeTheRun) {
  TempDir dir;
  fs::create_directory(dir.file("run.xdmf"));  // a directory where the sidecar would go
  RecorderOptions options;
  options.overwrite = true;
  EXPECT_THAT(creation_error(dir.file("run.h5"), options),
              HasSubstr("cannot write the XDMF sidecar '" + dir.file("run.xdmf") +
                        "': it exists and is not a file"));
  EXPECT_FALSE(fs::exists(dir.file("run.h5")));

  const std::string read_only = dir.file("ro");
  fs::create_directory(read_only);
  write(read_only + "/run.h5", "old");  // replaceable, but its directory takes no new file
  chmod(read_only.c_str(), 0555);
  if (access(read_only.c_str(), W_OK) != 0) {  // not when the tests run as root
    EXPECT_THAT(creation_error(read_only + "/run.h5", options), HasSubstr("cannot"));
    EXPECT_EQ(contents(read_only + "/run.h5"), "old");
  }
  chmod(read_only.c_str(), 0755);
}

TEST(OutputFiles, OverwriteReplacesTheFileOnlyOnceTheNewRecordingIsComplete) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  write(path, "old recording");
  write(dir.file("run.xdmf"), "old sidecar");
  Simulator sim = testing::slope_sim();
  RecorderOptions options;
  options.overwrite = true;
  {
    H5Recorder recorder(path, sim, options);
    EXPECT_EQ(recorder.path(), path);
    sim.add_observer(recorder);
    bool checked = false;
    testing::Probe probe([&](const Simulator& s) {
      if (checked || s.state().t < 0.2) return;
      checked = true;  // mid-run: the old files are untouched, the new one is beside them
      EXPECT_EQ(contents(path), "old recording");
      EXPECT_EQ(contents(dir.file("run.xdmf")), "old sidecar");
      EXPECT_EQ(partial_files(dir.file("")), 1);
    });
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(0.5).ok());
    EXPECT_TRUE(checked);
  }
  EXPECT_EQ(read_recording(path).frames(), 26);
  EXPECT_THAT(contents(dir.file("run.xdmf")), HasSubstr("<Xdmf"));
  EXPECT_EQ(partial_files(dir.file("")), 0);
}

TEST(OutputFiles, AnUnfinishedReplacementLeavesTheOldFile) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  write(path, "old recording");
  Simulator sim = testing::slope_sim();
  RecorderOptions options;
  options.overwrite = true;
  struct Failure {};
  {
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    testing::Probe fail([](const Simulator& s) {
      if (s.state().t > 0.2) throw Failure{};  // the run ends before on_finish
    });
    sim.add_observer(fail);
    EXPECT_THROW(sim.run_until(0.5), Failure);
  }
  EXPECT_EQ(contents(path), "old recording");
  EXPECT_FALSE(fs::exists(dir.file("run.xdmf")));
  EXPECT_EQ(partial_files(dir.file("")), 0);
}

// Issue 44, item 9: a second recorder told to overwrite a file that a first one still writes
// is refused (the first holds a write lock on it), whether the first writes the file in place or
// replaces an older one; once the first has finished, the second may replace it.
TEST(OutputFiles, ASecondWriterIsRefusedWhileTheFirstWrites) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  RecorderOptions overwrite;
  overwrite.overwrite = true;
  for (const bool first_replaces : {false, true}) {
    Simulator sim = testing::slope_sim();
    {
      H5Recorder first(path, sim, first_replaces ? overwrite : RecorderOptions{});
      sim.add_observer(first);
      sim.run_until(0.01);
      EXPECT_THAT(creation_error(path, overwrite),
                  HasSubstr("'" + path + "' is being written by another run"));
      sim.remove_observer(first);
    }
    EXPECT_EQ(creation_error(path, overwrite), "");
  }
  EXPECT_EQ(partial_files(dir.path().string()), 0);
}

}  // namespace
}  // namespace jelly
