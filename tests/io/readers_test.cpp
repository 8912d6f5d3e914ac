// Recordings and checkpoints whose datasets disagree with each other (a damaged or hand-edited
// file) are InputErrors naming the dataset, never reads out of bounds; checkpoints with absurd
// times are refused before a run could hang on them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <hdf5.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

#include "io/io_support.hpp"
#include "support/h5_damage.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

// A short slope run recorded to `path` (27 particles, 185 springs, 26 frames).
void record_slope_run(const std::string& path) {
  Simulator sim = testing::slope_sim(ContactModel::kSeed);
  RecorderOptions options;
  options.write_xdmf = false;
  options.scene_json = R"({"integrator": {"name": "rk4"}, "duration": 1})";
  H5Recorder recorder(path, sim, options);
  sim.add_observer(recorder);
  ASSERT_TRUE(sim.run_until(0.5).ok());
}

// Replaces dataset `name` of the file by `values` shaped `dims` (type double or int).
template <typename T>
void replace(const std::string& path, const std::string& name, const std::vector<hsize_t>& dims,
             const std::vector<T>& values) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  ASSERT_GE(H5Ldelete(file, name.c_str(), H5P_DEFAULT), 0) << name;
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const bool is_int = std::is_same<T, int>::value;
  const hid_t dataset = H5Dcreate2(file, name.c_str(), is_int ? H5T_STD_I32LE : H5T_IEEE_F64LE,
                                   space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(dataset, 0) << name;
  if (!values.empty()) {
    H5Dwrite(dataset, is_int ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
             values.data());
  }
  H5Dclose(dataset);
  H5Sclose(space);
  H5Fclose(file);
}

// Replaces attribute `name` of `object` by an array of doubles.
void replace_attribute(const std::string& path, const std::string& object, const std::string& name,
                       const std::vector<double>& values) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t group = H5Oopen(file, object.c_str(), H5P_DEFAULT);
  H5Adelete(group, name.c_str());
  const hsize_t n = values.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t attribute =
      H5Acreate2(group, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attribute, H5T_NATIVE_DOUBLE, values.data());
  H5Aclose(attribute);
  H5Sclose(space);
  H5Oclose(group);
  H5Fclose(file);
}

std::string recording_error(const std::string& path) {
  try {
    read_recording(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string checkpoint_error(const std::string& path) {
  try {
    Simulator sim = testing::slope_sim(ContactModel::kSeed);
    restore(sim, read_checkpoint(path));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

class DamagedRecording : public ::testing::Test {
 protected:
  void SetUp() override { record_slope_run(path_); }
  TempDir dir_;
  const std::string path_ = dir_.file("run.h5");
};

TEST_F(DamagedRecording, TheUndamagedFileReads) {
  EXPECT_EQ(recording_error(path_), "");
  EXPECT_EQ(checkpoint_error(path_), "");
}

// A run killed while HDF5 wrote can leave its last chunk named in the index but not stored:
// here the last stored chunk of the positions is overwritten so that it does not inflate, and
// the status is a killed run's ("running"). The reader keeps the frames before it (the same
// values as undamaged) instead of refusing the file.
TEST_F(DamagedRecording, AnUnreadableLastChunkKeepsTheFramesBeforeIt) {
  const Recording whole = read_recording(path_);
  testing::set_string_attribute(path_, "/parameters", "run_status", "running");
  const long first_frame = testing::corrupt_chunk(path_, "/particles/jelly/position/value", -1);
  ASSERT_GT(first_frame, 0);
  const Recording damaged = read_recording(path_);
  ASSERT_EQ(damaged.frames(), static_cast<int>(first_frame));
  for (int f = 0; f < damaged.frames(); ++f) {
    EXPECT_EQ(damaged.position[f], whole.position[f]) << "frame " << f;
    EXPECT_EQ(damaged.velocity[f], whole.velocity[f]) << "frame " << f;
    EXPECT_EQ(damaged.time[f], whole.time[f]) << "frame " << f;
  }
}

// Issue 44, item 10a: a corrupt chunk is damage, an InputError naming the file and the dataset,
// when the run finished (it stored every frame) or when frames after it read (a killed run loses
// only its last ones). Before, a corrupt first chunk read as a recording of 0 frames.
TEST_F(DamagedRecording, ACorruptChunkOfAFinishedRunIsAnError) {
  ASSERT_EQ(testing::corrupt_chunk(path_, "/particles/jelly/position/value", 0), 0);
  const std::string error = recording_error(path_);
  EXPECT_THAT(error, HasSubstr("'" + path_ + "' is not a readable jelly recording"));
  EXPECT_THAT(error, HasSubstr("/particles/jelly/position/value"));
}

TEST_F(DamagedRecording, ACorruptChunkBeforeReadableFramesIsAnError) {
  testing::set_string_attribute(path_, "/parameters", "run_status", "running");
  ASSERT_EQ(testing::corrupt_chunk(path_, "/particles/jelly/velocity/value", 0), 0);
  const std::string error = recording_error(path_);
  EXPECT_THAT(error, HasSubstr("frame 0 of /particles/jelly/velocity/value of 26 does not read"));
  EXPECT_THAT(error, HasSubstr(path_));
}

// A checkpoint whose state is not finite is a damaged file (InputError, exit 2), not a run that
// diverges when continued (exit 3).
TEST_F(DamagedRecording, ACheckpointThatIsNotFiniteIsAnError) {
  std::vector<double> x(81, 0.5);
  x[4] = std::nan("");
  replace<double>(path_, "/checkpoint/position", {27, 3}, x);
  EXPECT_THAT(checkpoint_error(path_),
              HasSubstr("'" + path_ +
                        "' has an invalid /checkpoint: /checkpoint/position of "
                        "particle 1 is nan (not finite: the file is damaged)"));
  testing::set_string_attribute(path_, "/parameters", "run_status", "diverged");
  EXPECT_THAT(checkpoint_error(path_), HasSubstr("its run diverged"));
}

TEST_F(DamagedRecording, SpringArraysOfDifferentLengths) {
  replace<double>(path_, "/connectivity/ks", {3}, {1, 2, 3});
  EXPECT_THAT(recording_error(path_), HasSubstr("/connectivity/ks: 3 values for 185 springs"));
}

TEST_F(DamagedRecording, FewerSpringPairsThanSprings) {
  replace<int>(path_, "/connectivity/springs", {1, 2}, {0, 1});
  EXPECT_THAT(recording_error(path_),
              HasSubstr("/connectivity/springs: 2 indices for 185 springs"));
}

TEST_F(DamagedRecording, SpringsBetweenParticlesThatDoNotExist) {
  std::vector<int> pairs(2 * 185, 0);
  for (int i = 0; i < 185; ++i) pairs[2 * i + 1] = 1 + i % 26;
  pairs[0] = 1000;
  replace<int>(path_, "/connectivity/springs", {185, 2}, pairs);
  EXPECT_THAT(recording_error(path_),
              HasSubstr("its model is invalid: springs[0].a = 1000 is invalid: a particle index "
                        "in [0, 27)"));
}

TEST_F(DamagedRecording, UnknownSpringTypes) {
  replace<int>(path_, "/connectivity/type", {185}, std::vector<int>(185, 7));
  EXPECT_THAT(recording_error(path_), HasSubstr("spring 0 has type 7"));
}

TEST_F(DamagedRecording, FramesOfAnotherParticleCount) {
  replace<double>(path_, "/particles/jelly/position/value", {2, 5, 3},
                  std::vector<double>(30, 0.0));
  EXPECT_THAT(recording_error(path_), HasSubstr("/particles/jelly/position/value: not [T][27][3]"));
  replace<double>(path_, "/particles/jelly/rest_position", {4}, {1, 2, 3, 4});
  EXPECT_THAT(recording_error(path_),
              HasSubstr("/particles/jelly/rest_position: 4 numbers for 27 particles"));
}

TEST_F(DamagedRecording, ObservablesOfAnotherShape) {
  replace<double>(path_, "/observables/center_of_mass/value", {2, 2, 2},
                  std::vector<double>(8, 0.0));
  EXPECT_THAT(recording_error(path_), HasSubstr("/observables/center_of_mass: not [T] or [T][3]"));
}

TEST_F(DamagedRecording, DatasetsClaimingMoreThanMemoryAreRefusedBeforeAllocating) {
  const hid_t file = H5Fopen(path_.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  H5Ldelete(file, "/particles/jelly/mass", H5P_DEFAULT);
  const hsize_t huge = hsize_t{1} << 40, chunk = 1024;
  const hid_t space = H5Screate_simple(1, &huge, nullptr);
  const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
  H5Pset_chunk(properties, 1, &chunk);  // chunked: no storage until written
  const hid_t dataset = H5Dcreate2(file, "/particles/jelly/mass", H5T_IEEE_F64LE, space,
                                   H5P_DEFAULT, properties, H5P_DEFAULT);
  H5Dclose(dataset);
  H5Pclose(properties);
  H5Sclose(space);
  H5Fclose(file);
  EXPECT_THAT(
      recording_error(path_),
      HasSubstr("dataset /particles/jelly/mass claims more values than it stores (0 bytes)"));
}

TEST_F(DamagedRecording, CheckpointSeedContactArraysOfDifferentLengths) {
  replace<int>(path_, "/checkpoint/seed_particle", {4}, {0, 1, 2, 3});
  replace<double>(path_, "/checkpoint/seed_friction", {1}, {0.5});
  EXPECT_THAT(checkpoint_error(path_),
              HasSubstr("seed_particle, seed_normal and seed_friction hold 4, "));
}

TEST_F(DamagedRecording, CheckpointVelocitiesOfAnotherSize) {
  replace<double>(path_, "/checkpoint/velocity", {2, 3}, std::vector<double>(6, 0.0));
  EXPECT_THAT(checkpoint_error(path_), HasSubstr("velocity is not the shape of position"));
}

TEST_F(DamagedRecording, ArrayAttributesWhereOneValueBelongs) {
  // Reading the first of several values into a single double overran the stack.
  replace_attribute(path_, "/checkpoint", "t", {1, 2, 3, 4});
  EXPECT_THAT(checkpoint_error(path_), HasSubstr("attribute t holds 4 values, not one"));
}

TEST_F(DamagedRecording, CheckpointTimesFarFromTheRunAreRefused) {
  // The first frame after a restore would step the next output time across the gap one
  // interval at a time: for an absurd value, a hang.
  replace_attribute(path_, "/checkpoint", "next_output", {-1e300});
  EXPECT_THAT(checkpoint_error(path_),
              HasSubstr("checkpoint next_output = -1.0000000000000001e+300 "
                        "is invalid: a time within an output interval"));
}

// A pipe blocked HDF5's first read for ever (jelly info, Python's read_recording).
TEST(Readers, APipeIsRefusedBeforeItIsOpened) {
  TempDir dir;
  const std::string fifo = dir.file("pipe.h5");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  for (const auto& read : {std::function<void()>([&] { read_recording(fifo); }),
                           std::function<void()>([&] { read_checkpoint(fifo); })}) {
    try {
      read();
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("it is a pipe, not a file"));
    }
  }
}

}  // namespace
}  // namespace jelly
