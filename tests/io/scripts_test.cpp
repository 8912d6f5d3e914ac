#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <jelly/io/h5_recorder.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

std::string record(const std::string& path) {
  Simulator sim = testing::slope_sim(ContactModel::kCoulomb, 4, "rk4", 0.05);
  H5Recorder recorder(path, sim);
  sim.add_observer(recorder);
  sim.run_until(1.0);
  return path;
}

bool is_png(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  return in && std::string(magic + 1, 3) == "PNG";
}

TEST(Scripts, PlotWritesAPng) {
  if (!testing::python_has("h5py, matplotlib")) GTEST_SKIP() << "no h5py or matplotlib";
  testing::TempDir dir;
  const std::string h5 = record(dir.file("run.h5")), png = dir.file("run.png");
  const std::string command =
      "/usr/bin/python3 " JELLY_SOURCE_DIR "/scripts/plot.py " + h5 + " -o " + png + " >/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 10000u);
  EXPECT_TRUE(is_png(png));
}

TEST(Scripts, AnimateWritesAVideo) {
  if (!testing::python_has("h5py, matplotlib")) GTEST_SKIP() << "no h5py or matplotlib";
  testing::TempDir dir;
  const std::string h5 = record(dir.file("run.h5"));
  const std::string gif = dir.file("run.gif");
  const std::string command = "/usr/bin/python3 " JELLY_SOURCE_DIR "/scripts/animate.py " + h5 +
                              " -o " + gif + " --fps 10 --max-frames 6 >/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  ASSERT_TRUE(std::filesystem::exists(gif));
  EXPECT_GT(std::filesystem::file_size(gif), 1000u);
}

}  // namespace
}  // namespace jelly
