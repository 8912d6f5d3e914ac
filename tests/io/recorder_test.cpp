#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <hdf5.h>

#include <fstream>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

struct Frames {
  std::vector<Real> t;
  std::vector<long> step;
  std::vector<VecX> x, v;
};

// Records a short slope run to `path` and returns what the simulator showed at each frame.
Frames record_slope(const std::string& path, RecorderOptions options = {}) {
  Simulator sim = testing::slope_sim();
  H5Recorder recorder(path, sim, options);
  Frames frames;
  testing::Probe probe([&](const Simulator& s) {
    frames.t.push_back(s.state().t);
    frames.step.push_back(s.total_steps());
    frames.x.push_back(s.state().x);
    frames.v.push_back(s.state().v);
  });
  sim.add_observer(recorder);
  sim.add_observer(probe);
  EXPECT_TRUE(sim.run_until(0.5).ok());
  return frames;
}

// A recorder made for one simulator refuses another model's simulator when it is added (issue
// 38: a 27-particle recorder on an 8-particle simulator read past its arrays), naming both.
TEST(Recorder, RefusesTheSimulatorOfAnotherModel) {
  TempDir dir;
  Simulator small = testing::slope_sim(ContactModel::kCoulomb, 2);
  Simulator large = testing::slope_sim(ContactModel::kCoulomb, 3);
  H5Recorder recorder(dir.file("large.h5"), large);
  try {
    small.add_observer(recorder);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("simulator = 8 particles"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("27 particles"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("large.h5"));
  }
  EXPECT_EQ(small.num_observers(), 0u);
  // The simulator it was made for, or another of the same model, is accepted.
  Simulator same = testing::slope_sim(ContactModel::kCoulomb, 3);
  same.add_observer(recorder);
  large.add_observer(recorder);
  EXPECT_TRUE(large.run_until(0.01).ok());
}

// leave_simulators() removes an observer from every simulator it was added to.
TEST(Recorder, LeavesEverySimulator) {
  Simulator a = testing::slope_sim(), b = testing::slope_sim();
  testing::Probe probe([](const Simulator&) {});
  a.add_observer(probe);
  b.add_observer(probe);
  probe.leave_simulators();
  EXPECT_EQ(a.num_observers(), 0u);
  EXPECT_EQ(b.num_observers(), 0u);
  EXPECT_FALSE(a.remove_observer(probe));
}

class RoundTrip : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(Writer, RoundTrip, ::testing::Values(true, false),
                         [](const auto& p) { return p.param ? "background" : "inline"; });

// What was written is read back equal: the model and every frame, bit for bit.
TEST_P(RoundTrip, ModelAndFramesReadBackEqual) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  RecorderOptions options;
  options.background_writer = GetParam();
  options.flush_every_frames = 3;  // 26 frames: 8 full blocks and a partial one at the end
  options.scene_json = R"({"name": "slope"})";
  const Frames frames = record_slope(path, options);
  ASSERT_EQ(frames.t.size(), 26u);

  const Recording r = read_recording(path);
  const Model expected = build_cube(testing::small_cube(3, 1.0, Vec3(-0.5, 0.4, -0.5)));
  EXPECT_EQ(r.model.mass, expected.mass);
  EXPECT_EQ(r.model.rest_position, expected.rest_position);
  EXPECT_EQ(r.model.gravity, expected.gravity);
  EXPECT_EQ(r.model.springs.a, expected.springs.a);
  EXPECT_EQ(r.model.springs.b, expected.springs.b);
  EXPECT_EQ(r.model.springs.rest_length, expected.springs.rest_length);
  EXPECT_EQ(r.model.springs.ks, expected.springs.ks);
  EXPECT_EQ(r.model.springs.kd, expected.springs.kd);
  EXPECT_EQ(r.model.springs.type, expected.springs.type);

  ASSERT_EQ(r.frames(), 26);
  EXPECT_EQ(r.time, frames.t);
  EXPECT_EQ(r.step, frames.step);
  for (int f = 0; f < r.frames(); ++f) {
    EXPECT_EQ(r.position[f], frames.x[f]) << "frame " << f;
    EXPECT_EQ(r.velocity[f], frames.v[f]) << "frame " << f;
  }
  // Observables are the measures of core/, per frame.
  ASSERT_EQ(r.observables.size(), 7u);
  const int f = 20;
  EXPECT_DOUBLE_EQ(r.observables.at("kinetic_energy")(f, 0), kinetic_energy(expected, frames.v[f]));
  EXPECT_DOUBLE_EQ(r.observables.at("total_energy")(f, 0),
                   kinetic_energy(expected, frames.v[f]) + elastic_energy(expected, frames.x[f]) +
                       gravitational_energy(expected, frames.x[f]));
  const Vec3 com = center_of_mass(expected, frames.x[f]);
  EXPECT_EQ(r.observables.at("center_of_mass").row(f).transpose(), com);
  EXPECT_EQ(r.observables.at("angular_momentum").cols(), 3);

  ASSERT_EQ(r.terrains.size(), 1u);
  EXPECT_EQ(r.terrains[0].name, "0_plane");
  EXPECT_EQ(r.terrains[0].position.size(), 26u);
  EXPECT_EQ(r.scene_json, options.scene_json);
  EXPECT_EQ(r.attributes.at("integrator"), "rk4");
  EXPECT_EQ(r.attributes.at("run_status"), "completed");
  EXPECT_EQ(r.attributes.at("run_steps"), "500");
  EXPECT_EQ(r.attributes.at("statistics.steps"), "500");
}

// Dimensions of a dataset, or an empty vector when it does not exist.
std::vector<hsize_t> shape(hid_t file, const char* path) {
  if (H5Lexists(file, path, H5P_DEFAULT) <= 0) return {};
  const hid_t d = H5Dopen2(file, path, H5P_DEFAULT);
  const hid_t s = H5Dget_space(d);
  std::vector<hsize_t> dims(H5Sget_simple_extent_ndims(s));
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  H5Sclose(s);
  H5Dclose(d);
  return dims;
}

bool has_attribute(hid_t file, const char* object, const char* name) {
  return H5Aexists_by_name(file, object, name, H5P_DEFAULT) > 0;
}

// The layout of docs/output.md, by name and shape, read with the HDF5 C API.
TEST(Layout, NamesAndShapes) {
  TempDir dir;
  const std::string path = dir.file("layout.h5");
  record_slope(path);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  using D = std::vector<hsize_t>;
  const hsize_t T = 26, N = 27, M = build_cube(testing::small_cube(3)).springs.size();
  for (const char* a : {"version", "creator", "creator_version"}) {
    EXPECT_TRUE(has_attribute(file, "/h5md", a)) << a;
  }
  for (const char* a : {"scene_json", "integrator", "dt", "output_interval", "library_version",
                        "run_status", "run_reason", "run_steps", "run_wall_seconds",
                        "run_force_evaluations", "statistics.steps"}) {
    EXPECT_TRUE(has_attribute(file, "/parameters", a)) << a;
  }
  EXPECT_EQ(shape(file, "/particles/jelly/mass"), (D{N}));
  for (const char* group : {"position", "velocity"}) {
    const std::string g = std::string("/particles/jelly/") + group;
    EXPECT_EQ(shape(file, (g + "/step").c_str()), (D{T}));
    EXPECT_EQ(shape(file, (g + "/time").c_str()), (D{T}));
    EXPECT_EQ(shape(file, (g + "/value").c_str()), (D{T, N, 3}));
  }
  EXPECT_EQ(shape(file, "/connectivity/springs"), (D{M, 2}));
  for (const char* name : {"rest_length", "type", "ks", "kd"}) {
    EXPECT_EQ(shape(file, (std::string("/connectivity/") + name).c_str()), (D{M})) << name;
  }
  for (const char* name :
       {"kinetic_energy", "elastic_energy", "gravitational_energy", "total_energy"}) {
    const std::string g = std::string("/observables/") + name;
    EXPECT_EQ(shape(file, (g + "/value").c_str()), (D{T})) << name;
    EXPECT_EQ(shape(file, (g + "/time").c_str()), (D{T})) << name;
    EXPECT_EQ(shape(file, (g + "/step").c_str()), (D{T})) << name;
  }
  for (const char* name : {"center_of_mass", "linear_momentum", "angular_momentum"}) {
    EXPECT_EQ(shape(file, (std::string("/observables/") + name + "/value").c_str()), (D{T, 3}))
        << name;
  }
  EXPECT_EQ(shape(file, "/terrain/0_plane/position/value"), (D{T, 3}));
  EXPECT_EQ(shape(file, "/terrain/0_plane/position/time"), (D{T}));
  EXPECT_EQ(shape(file, "/checkpoint/position"), (D{N, 3}));

  // The time series are chunked along time and compressed.
  const hid_t d = H5Dopen2(file, "/particles/jelly/position/value", H5P_DEFAULT);
  const hid_t plist = H5Dget_create_plist(d);
  EXPECT_EQ(H5Pget_layout(plist), H5D_CHUNKED);
  hsize_t chunk[3];
  ASSERT_EQ(H5Pget_chunk(plist, 3, chunk), 3);
  EXPECT_GE(chunk[0], 1u);
  EXPECT_EQ(chunk[1], N);
  EXPECT_EQ(chunk[2], 3u);
  EXPECT_GT(H5Pget_nfilters(plist), 0);
  H5Pclose(plist);
  H5Dclose(d);
  H5Fclose(file);
}

// A block of frames held in memory is at most 8 MiB of particle data: with flush_every_frames =
// 1000, a cube of 11^3 = 1331 particles (63,888 bytes a frame: 131 fit) is flushed in blocks of
// 128 frames (the largest power of two that fits), so its position chunks hold 32 frames (the
// largest divisor of 128 whose chunk fits in 1 MiB; blocks of 1000 would give 25).
TEST(Layout, LargeFramesAreFlushedInSmallerBlocks) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  Simulator sim = testing::slope_sim(ContactModel::kCoulomb, 11);
  ASSERT_EQ(sim.model().num_particles(), 1331);
  RecorderOptions options;
  options.flush_every_frames = 1000;
  {
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(0.05).ok());
  }
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t d = H5Dopen2(file, "/particles/jelly/position/value", H5P_DEFAULT);
  const hid_t plist = H5Dget_create_plist(d);
  hsize_t chunk[3] = {0, 0, 0};
  EXPECT_EQ(H5Pget_chunk(plist, 3, chunk), 3);
  EXPECT_EQ(chunk[0], 32u);
  EXPECT_EQ(chunk[1], 1331u);
  H5Pclose(plist);
  H5Dclose(d);
  H5Fclose(file);
}

TEST(Describe, SummarisesTheRun) {
  TempDir dir;
  const std::string path = dir.file("info.h5");
  record_slope(path);
  const std::string text = describe_recording(path);
  for (const char* expected :
       {"creator:       jelly", "particles:     27", "frames:        26, t = 0 .. 0.5",
        "integrator:    rk4, dt = 0.001", "status:        completed", "kinetic_energy",
        "center_of_mass", "0_plane", "bytes"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  }
  EXPECT_NE(text.find("structural"), std::string::npos) << text;
}

TEST(Errors, UncreatablePathNamesThePath) {
  Simulator sim = testing::slope_sim();
  const std::string path = "/nonexistent-jelly-dir/out.h5";
  try {
    H5Recorder recorder(path, sim);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(Errors, MissingOrInvalidFileNamesTheFile) {
  TempDir dir;
  const std::string missing = dir.file("missing.h5");
  EXPECT_THROW(
      {
        try {
          read_recording(missing);
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
          throw;
        }
      },
      InputError);
  const std::string text = dir.file("text.h5");
  std::ofstream(text) << "not HDF5\n";
  for (auto read : {+[](const std::string& p) { read_recording(p); },
                    +[](const std::string& p) { describe_recording(p); }}) {
    try {
      read(text);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  }
  RecorderOptions options;
  options.flush_every_frames = 0;
  EXPECT_THROW(options.validate(), InputError);
}

}  // namespace
}  // namespace jelly
