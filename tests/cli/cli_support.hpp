#pragma once
// Running the jelly program as users do, for the CLI tests: exit code, stdout and stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "support/temp_dir.hpp"

namespace jelly::cli_testing {

struct Result {
  int code = -1;
  std::string out, err;
};

inline std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The directory of this test program's files: new for each run, so that no file of an earlier
// run can be taken for one of this run's (a path below is unique, but the names derived from it,
// an .h5's .xdmf sidecar, were not: an earlier run's leftover once failed a test), and removed
// at exit with whatever the tests left in it.
inline const jelly::testing::TempDir& test_dir() {
  static const jelly::testing::TempDir dir("jelly_cli");
  return dir;
}

// A fresh path in this run's directory.
inline std::string temp_path(const std::string& suffix) {
  std::string pattern = test_dir().file("XXXXXX");
  const int fd = mkstemp(pattern.data());
  if (fd >= 0) close(fd);
  std::remove(pattern.c_str());
  return pattern + suffix;
}

// Runs `jelly ARGS` with stdout and stderr captured (neither is a terminal); `shell` is run
// before it in the same shell (kFullDisk).
inline Result jelly(const std::string& args, const std::string& shell = "") {
  const std::string out = temp_path(".out");
  const std::string err = temp_path(".err");
  const std::string command =
      shell + "'" + JELLY_CLI + "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  const int status = std::system(command.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return r;
}

// As a disk that is full: every write of a file past its first 1,024 bytes fails (the file size
// limit, with its signal ignored, makes write() fail with EFBIG, for jelly and the programs it
// starts, such as ffmpeg).
inline const std::string kFullDisk = "trap '' XFSZ; ulimit -f 2; ";

inline std::string scene(const std::string& name) {
  return std::string(JELLY_SCENES_DIR) + "/" + name;
}

// The seed slope on a 3x3x3 cube: fast.
inline const std::string kSmallSlope = "'" + scene("seed_slope.json") + "' --set cube.n=3";

inline std::string write_scene(const std::string& text) {
  const std::string path = temp_path(".json");
  std::ofstream(path) << text;
  return path;
}

}  // namespace jelly::cli_testing
