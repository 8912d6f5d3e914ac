// The jelly program as an attacker or a careless user runs it (issue 16): no crash, no hang, no
// lost file, no silent run, and the documented exit codes. Each test is one class of finding.
#include <hdf5.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli/cli_support.hpp"
#include "support/h5_damage.hpp"

namespace jelly {
namespace {

using ::testing::AllOf;
using ::testing::AnyOf;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;
using namespace cli_testing;

std::string quoted(const std::string& path) { return "'" + path + "'"; }

bool exists(const std::string& path) {
  struct stat info {};
  return stat(path.c_str(), &info) == 0;
}

// A short recording of the small slope (0.1 s) at `path`.
void record(const std::string& path, const std::string& extra = "") {
  const Result r = jelly("run " + kSmallSlope + " --duration 0.1 -q -o " + quoted(path) + extra);
  ASSERT_EQ(r.code, 0) << r.err;
}

// Sets attribute `name` of `object` in an HDF5 file to a double or a string.
void set_attribute(const std::string& path, const std::string& object, const std::string& name,
                   double value) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t group = H5Oopen(file, object.c_str(), H5P_DEFAULT);
  const hid_t attribute = H5Aopen(group, name.c_str(), H5P_DEFAULT);
  H5Awrite(attribute, H5T_NATIVE_DOUBLE, &value);
  H5Aclose(attribute);
  H5Oclose(group);
  H5Fclose(file);
}

void set_attribute(const std::string& path, const std::string& object, const std::string& name,
                   const std::string& value) {
  testing::set_string_attribute(path, object, name, value);
}

// ---- Crashes ----

std::string nested(int depth) { return std::string(depth, '[') + std::string(depth, ']'); }

TEST(Crashes, DeeplyNestedJsonInASceneOrASetValueExitsTwo) {
  const std::string deep = write_scene(R"({"description": )" + nested(100000) +
                                       R"(, "integrator": {"name": "rk4"}, "duration": 1})");
  Result r = jelly("run " + quoted(deep));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("deeper than 64 levels at description[0][0]"));
  r = jelly("run " + kSmallSlope + " --set 'description=" + nested(30000) + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("deeper than 32 levels"));
  // A long path created the nesting itself.
  std::string path;
  for (int i = 0; i < 30000; ++i) path += "a.";
  r = jelly("run " + kSmallSlope + " --set '" + path + "a=1'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("' has more than 32 steps"));
}

TEST(Crashes, DeeplyNestedSceneStoredInARecordingExitsTwo) {
  const std::string file = temp_path(".h5");
  record(file);
  set_attribute(file, "/parameters", "scene_json", R"({"description": )" + nested(100000) + "}");
  Result r = jelly("fit " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("deeper than 64 levels"));
  r = jelly("run " + kSmallSlope + " --duration 0.2 --restart " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, AllOf(StartsWith("error: --restart "), HasSubstr("deeper than 64 levels")));
}

// ---- Data loss ----

TEST(DataLoss, ASecondRunDoesNotReplaceAnExistingRecording) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string before = read_file(file);
  // Not even when the second run would have failed (it diverges here).
  Result r =
      jelly("run " + kSmallSlope + " --integrator explicit_euler --dt 0.05 -o " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("exists (a file this run did not create): pass --overwrite"));
  EXPECT_EQ(read_file(file), before);
  // With --overwrite it is replaced once the new recording is complete.
  r = jelly("run " + kSmallSlope + " --duration 0.2 -q --overwrite -o " + quoted(file));
  ASSERT_EQ(r.code, 0) << r.err;
  r = jelly("info " + quoted(file));
  EXPECT_THAT(r.out, HasSubstr("t = 0 .. 0.2"));
}

TEST(DataLoss, TheSceneFileIsNeverTheOutput) {
  const std::string scene_file = write_scene(
      R"({"terrains": [{"kind": "slope"}], "cube": {"n": 3}, "integrator": {"name": "rk4"},
          "duration": 0.1})");
  const std::string before = read_file(scene_file);
  Result r = jelly("run " + quoted(scene_file) + " --overwrite -o " + quoted(scene_file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("is the scene file: the recording would overwrite it"));
  // Nor its sidecar: scene.xdmf as the scene, -o scene.h5.
  const std::string xdmf_scene = temp_path(".xdmf");
  std::rename(scene_file.c_str(), xdmf_scene.c_str());
  const std::string h5 = xdmf_scene.substr(0, xdmf_scene.size() - 5) + ".h5";
  r = jelly("run " + quoted(xdmf_scene) + " --overwrite -o " + quoted(h5));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("is the scene file: the run would overwrite it"));
  EXPECT_EQ(read_file(xdmf_scene), before);
}

TEST(DataLoss, ARecordingNamedXdmfIsRefused) {
  const std::string file = temp_path(".xdmf");
  const Result r = jelly("run " + kSmallSlope + " --duration 0.1 -o " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("name the recording .h5"));
  EXPECT_FALSE(exists(file));
}

TEST(DataLoss, ARestartNeverWritesOverItsCheckpointFile) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string before = read_file(file);
  const Result r = jelly("run " + kSmallSlope + " --duration 0.2 --overwrite --restart " +
                         quoted(file) + " -o " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("is the --restart file: the continuation would replace the frames"));
  EXPECT_EQ(read_file(file), before);
}

TEST(DataLoss, FitWritesNoSceneOverAnExistingFile) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string before = read_file(file);
  Result r = jelly("fit " + quoted(file) + " --write-scene " + quoted(file) + " --overwrite");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("is the recording " + file + " (the same file)"));
  EXPECT_EQ(read_file(file), before);
  const std::string other = write_scene("{}");
  r = jelly("fit " + quoted(file) + " --write-scene " + quoted(other));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("exists (a file this run did not create): pass --overwrite"));
  EXPECT_EQ(read_file(other), "{}");
}

// Files of this run's test folder (and its subfolders) whose name has ".partial-".
int partial_files() {
  int count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test_dir().path())) {
    if (entry.path().filename().string().find(".partial-") != std::string::npos) ++count;
  }
  return count;
}

// A unit cube as an OBJ surface (8 vertices, 12 triangles outward).
std::string cube_obj() {
  const std::string path = temp_path(".obj");
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                         "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                         "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  return path;
}

// Issue 44, item 8: with --overwrite, a write that fails (a full disk) exits 1 and leaves the
// old file byte for byte; without the failure the file is replaced. Before, each of these opened
// the old file for writing at once: the full disk left it truncated.
TEST(DataLoss, AFailedMeshWriteLeavesTheOldFileAsItWas) {
  const std::string surface = cube_obj();
  const std::string out = temp_path(".msh");
  std::ofstream(out) << "precious";
  Result r = jelly("mesh " + quoted(surface) + " -o " + quoted(out) + " --size 0.2 --overwrite",
                   kFullDisk);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("cannot write '" + out + "'"));
  EXPECT_EQ(read_file(out), "precious");
  EXPECT_EQ(partial_files(), 0);
  r = jelly("mesh " + quoted(surface) + " -o " + quoted(out) + " --size 0.2 --overwrite");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(read_file(out), StartsWith("$MeshFormat"));
}

TEST(DataLoss, AFailedExportLeavesTheOldFilesAsTheyWere) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string folder = temp_path("");
  std::filesystem::create_directory(folder);
  const std::string frame = folder + "/frame_0000.obj";
  std::ofstream(frame) << "precious";
  Result r = jelly("export " + quoted(file) + " --obj-sequence " + quoted(folder) + " --overwrite",
                   kFullDisk);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(read_file(frame), "precious");
  // No frame of the new sequence either: every frame is written before any is renamed.
  EXPECT_FALSE(exists(folder + "/frame_0001.obj"));
  const std::string pc2 = temp_path(".pc2");
  const std::string rest = pc2.substr(0, pc2.size() - 4) + ".obj";
  std::ofstream(pc2) << "precious cache";
  std::ofstream(rest) << "precious surface";
  r = jelly("export " + quoted(file) + " --pc2 " + quoted(pc2) + " --overwrite", kFullDisk);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(read_file(pc2), "precious cache");
  EXPECT_EQ(read_file(rest), "precious surface");
  EXPECT_EQ(partial_files(), 0);
  const std::string glb = temp_path(".glb");
  std::ofstream(glb) << "precious scene";
  r = jelly("export " + quoted(file) + " --gltf " + quoted(glb) + " --overwrite", kFullDisk);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(read_file(glb), "precious scene");
  EXPECT_EQ(partial_files(), 0);
  r = jelly("export " + quoted(file) + " --obj-sequence " + quoted(folder) + " --pc2 " +
            quoted(pc2) + " --gltf " + quoted(glb) + " --overwrite");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(read_file(frame), StartsWith("# jelly render surface"));
  EXPECT_THAT(read_file(pc2), StartsWith("POINTCACHE2"));
  EXPECT_THAT(read_file(glb), StartsWith("glTF"));
}

// An OBJ sequence written over a longer one leaves no frame of the old one behind (issue 44):
// with --overwrite the old frames past the new last are removed, and only files named as frames
// are; without it any earlier frame (not only frame_0000) is refused.
TEST(DataLoss, AnObjSequenceOverALongerOneLeavesNoOldFrame) {
  const std::string file = temp_path(".h5");
  record(file);  // 0.1 s: a few frames
  const std::string folder = temp_path("");
  std::filesystem::create_directory(folder);
  std::ofstream(folder + "/frame_0030.obj") << "an earlier sequence";
  Result r = jelly("export " + quoted(file) + " --obj-sequence " + quoted(folder));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_THAT(r.err, AllOf(HasSubstr("frame_0030.obj exists"), HasSubstr("--overwrite")));
  EXPECT_FALSE(exists(folder + "/frame_0000.obj"));

  for (int k = 0; k < 40; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%04d.obj", k);
    std::ofstream(folder + name) << "an earlier sequence";
  }
  // Not frames of a sequence: kept.
  const std::vector<std::string> others = {"/frame_7.obj", "/frame_00001.obj", "/frame_0050.OBJ",
                                           "/frame_0051.obj.txt", "/notes.txt"};
  for (const std::string& name : others) std::ofstream(folder + name) << "keep";
  std::filesystem::create_directory(folder + "/frame_0060.obj");
  r = jelly("export " + quoted(file) + " --obj-sequence " + quoted(folder) + " --overwrite");
  ASSERT_EQ(r.code, 0) << r.err;
  int frames = 0;
  ASSERT_EQ(std::sscanf(r.out.c_str(), "wrote %d OBJ files", &frames), 1) << r.out;
  ASSERT_GT(frames, 1);
  ASSERT_LT(frames, 40);
  for (int k = 0; k < 40; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%04d.obj", k);
    if (k < frames) {
      EXPECT_THAT(read_file(folder + name), StartsWith("# jelly render surface")) << name;
    } else {
      EXPECT_FALSE(exists(folder + name)) << name << " of the earlier sequence was left";
    }
  }
  for (const std::string& name : others) EXPECT_EQ(read_file(folder + name), "keep") << name;
  EXPECT_TRUE(std::filesystem::is_directory(folder + "/frame_0060.obj"));
}

// The scene of `jelly fit --write-scene` and the sidecar of `jelly xdmf` go through the same
// replacement.
TEST(DataLoss, AFailedSceneOrSidecarWriteLeavesTheOldFileAsItWas) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string sidecar = file.substr(0, file.size() - 3) + ".xdmf";
  const std::string before = read_file(sidecar);
  ASSERT_GT(before.size(), 1024u);
  Result r = jelly("xdmf " + quoted(file) + " --overwrite", kFullDisk);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(read_file(sidecar), before);
  EXPECT_EQ(partial_files(), 0);
}

// `jelly xdmf` writes the sidecar beside the recording and its views (virtual datasets and
// derived arrays, group /xdmf) into the recording: without --overwrite an existing sidecar is
// refused and the recording is left byte for byte; with it the views are brought up to date and
// the sidecar replaced. The views are written into a copy renamed onto the recording: written in
// place, a rebuild that failed on a full disk left a recording no reader could open ("bad heap
// free list"; issue 44). Now the recording is as it was and the next call completes the views.
TEST(DataLoss, XdmfUpdatesTheRecordingsViewsAndAFailureLeavesItAsItWas) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string sidecar = file.substr(0, file.size() - 3) + ".xdmf";
  const std::string recording = read_file(file);
  const auto frames_line = [&] {
    const Result r = jelly("info " + quoted(file));
    EXPECT_EQ(r.code, 0) << r.err;
    const std::size_t at = r.out.find("frames:");
    return at == std::string::npos ? r.out : r.out.substr(at, r.out.find('\n', at) - at);
  };
  const std::string frames = frames_line();
  ASSERT_THAT(frames, StartsWith("frames:"));
  Result r = jelly("xdmf " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("exists: pass --overwrite"));
  EXPECT_EQ(read_file(file), recording);

  // The views removed (as in a recording of a run killed before it wrote them): a rebuild that
  // cannot write.
  const hid_t h5 = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(h5, 0);
  ASSERT_GE(H5Ldelete(h5, "/xdmf", H5P_DEFAULT), 0);
  H5Fclose(h5);
  std::filesystem::remove(sidecar);
  const std::string without_views = read_file(file);
  r = jelly("xdmf " + quoted(file), kFullDisk);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_FALSE(exists(sidecar));
  EXPECT_EQ(read_file(file), without_views);
  EXPECT_EQ(frames_line(), frames);
  EXPECT_EQ(partial_files(), 0);

  r = jelly("xdmf " + quoted(file));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(read_file(sidecar), HasSubstr("<Xdmf"));
  r = jelly("xdmf " + quoted(file) + " --overwrite");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(frames_line(), frames);
  r = jelly("export " + quoted(file) + " --pc2 " + quoted(temp_path(".pc2")));
  EXPECT_EQ(r.code, 0) << r.err;
}

// Issue 44, item 9: an output that is an input of the command, also through a hard or a
// symbolic link, is refused (exit 2) naming both, and the input is untouched.
TEST(DataLoss, AnOutputThatIsTheInputIsRefusedNamingBoth) {
  const std::string surface = cube_obj();
  const std::string msh = temp_path(".msh");
  ASSERT_EQ(link(surface.c_str(), msh.c_str()), 0);
  const std::string before = read_file(surface);
  Result r = jelly("mesh " + quoted(surface) + " -o " + quoted(msh) + " --size 0.2 --overwrite");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("-o " + msh + " is the input surface " + surface));
  EXPECT_EQ(read_file(surface), before);

  const std::string file = temp_path(".h5");
  record(file);
  const std::string recording = read_file(file);
  const std::string folder = temp_path("");
  std::filesystem::create_directory(folder);
  ASSERT_EQ(link(file.c_str(), (folder + "/frame_0000.obj").c_str()), 0);
  const std::string pc2 = temp_path(".pc2");
  std::filesystem::create_symlink(file, pc2);
  const std::string scene = temp_path(".json");
  std::filesystem::create_symlink(file, scene);
  const std::string glb = temp_path(".glb");
  ASSERT_EQ(link(file.c_str(), glb.c_str()), 0);
  const std::string sidecar = file.substr(0, file.size() - 3) + ".xdmf";
  std::remove(sidecar.c_str());
  ASSERT_EQ(link(file.c_str(), sidecar.c_str()), 0);
  for (const std::string& command :
       {"export " + quoted(file) + " --obj-sequence " + quoted(folder) + " --overwrite",
        "export " + quoted(file) + " --pc2 " + quoted(pc2) + " --overwrite",
        "export " + quoted(file) + " --gltf " + quoted(glb) + " --overwrite",
        "fit " + quoted(file) + " --write-scene " + quoted(scene) + " --overwrite",
        "xdmf " + quoted(file) + " --overwrite"}) {
    r = jelly(command);
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_THAT(r.err, HasSubstr(file)) << command;
    EXPECT_THAT(r.err, HasSubstr("(the same file)")) << command;
  }
  EXPECT_EQ(read_file(file), recording);
}

// Issue 44, item 9: `jelly run -o` naming a mesh file the scene reads (here a tet mesh body's,
// through a hard link) is refused naming both; before, --overwrite replaced it.
TEST(DataLoss, ARunNeverWritesOverAMeshFileOfItsScene) {
  const std::string msh = temp_path(".msh");
  Result r = jelly("mesh " + quoted(cube_obj()) + " -o " + quoted(msh) + " --size 0.5");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string before = read_file(msh);
  const std::string scene_file =
      write_scene(R"({"bodies": [{"kind": "tetmesh", "file": ")" + msh +
                  R"("}], "integrator": {"name": "rk4"}, "duration": 0.01})");
  const std::string out = temp_path(".h5");
  ASSERT_EQ(link(msh.c_str(), out.c_str()), 0);
  r = jelly("run " + quoted(scene_file) + " -q --overwrite -o " + quoted(out));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("-o " + out + " is the mesh file " + msh));
  EXPECT_EQ(read_file(msh), before);
}

// Issue 44, item 9: while another program writes a file (it holds the write lock every jelly
// writer takes: here this test does, as a first run would), a second jelly told to --overwrite
// it is refused, exit 2, and leaves it alone; once the lock is released it may replace it.
TEST(DataLoss, ASecondWriterIsRefusedWhileTheFileIsBeingWritten) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string msh = temp_path(".msh");
  std::ofstream(msh) << "precious";
  const std::string before = read_file(file);
  std::vector<int> locks;
  for (const std::string& path : {file, msh}) {
    const int fd = open(path.c_str(), O_WRONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    struct flock lock {};
    lock.l_type = F_WRLCK;
    lock.l_whence = SEEK_SET;
    ASSERT_EQ(fcntl(fd, F_OFD_SETLK, &lock), 0);
    locks.push_back(fd);
  }
  const std::string run =
      "run " + kSmallSlope + " --duration 0.1 -q --overwrite -o " + quoted(file);
  const std::string mesh = "mesh " + quoted(cube_obj()) + " -o " + quoted(msh) + " --overwrite";
  for (const std::string& command : {run, mesh}) {
    const Result r = jelly(command);
    EXPECT_EQ(r.code, 2) << command << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr("is being written by another run")) << command;
  }
  EXPECT_EQ(read_file(file), before);
  EXPECT_EQ(read_file(msh), "precious");
  EXPECT_EQ(partial_files(), 0);
  for (const int fd : locks) close(fd);
  EXPECT_EQ(jelly(run).code, 0);
  EXPECT_EQ(jelly(mesh).code, 0);
}

// ---- Damaged files ----

// Writes `value` over every element of the double dataset `name`, in place.
void fill_dataset(const std::string& path, const std::string& name, double value) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t dataset = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(dataset);
  const std::vector<double> values(static_cast<size_t>(H5Sget_simple_extent_npoints(space)), value);
  H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(dataset);
  H5Fclose(file);
}

// Issue 44, item 10a: one validation of a recording for every reader. A corrupt compressed
// chunk of a finished run and masses that are not finite exit 2 naming the file and the dataset,
// in info, export, xdmf and fit alike (before: export wrote 0 frames and exited 0, info
// described 7 frames, xdmf rewrote the sidecar).
TEST(DamagedFiles, EveryReaderRefusesADamagedRecordingNamingTheDataset) {
  for (const std::string damage : {"chunk", "mass"}) {
    const std::string file = temp_path(".h5");
    record(file);
    std::string dataset;
    if (damage == "chunk") {
      dataset = "/particles/jelly/position/value";
      ASSERT_EQ(testing::corrupt_chunk(file, dataset, 0), 0);
    } else {
      dataset = "its model is invalid: mass";
      fill_dataset(file, "/particles/jelly/mass", std::nan(""));
    }
    for (const std::string& command :
         {"info " + quoted(file), "export " + quoted(file) + " --pc2 " + quoted(temp_path(".pc2")),
          "xdmf " + quoted(file) + " --overwrite", "fit " + quoted(file)}) {
      const Result r = jelly(command);
      EXPECT_EQ(r.code, 2) << damage << ": " << command << ": " << r.err;
      EXPECT_THAT(r.err, HasSubstr("'" + file + "' is not a readable jelly recording"))
          << damage << ": " << command;
      EXPECT_THAT(r.err, HasSubstr(dataset)) << damage << ": " << command;
    }
  }
}

// A checkpoint whose positions are not finite is a damaged file (exit 2), not a divergence of
// the continued run (exit 3, before).
TEST(DamagedFiles, ARestartFromACheckpointThatIsNotFiniteExitsTwo) {
  const std::string file = temp_path(".h5");
  record(file);
  fill_dataset(file, "/checkpoint/position", std::nan(""));
  const Result r = jelly("run " + kSmallSlope + " --duration 0.2 -q --restart " + quoted(file) +
                         " -o " + quoted(temp_path(".h5")));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("/checkpoint/position of particle 0 is nan"));
  EXPECT_THAT(r.err, HasSubstr(file));
}

// Issue 44, item 10: values that were taken silently. `render --start NaN` meant "the
// recording's start", `view --frame` past the recording showed its last frame, and an empty
// `--screenshot` name meant "no screenshot" (and exit 0). Each is refused before a window or an
// offscreen context is opened.
TEST(Silent, NaNTimesFramesOutOfRangeAndEmptyNamesAreRefused) {
  const std::string file = temp_path(".h5");
  record(file);
  for (const auto& [command, field] : std::vector<std::pair<std::string, std::string>>{
           {"render " + quoted(file) + " -o " + quoted(temp_path(".mp4")) + " --start nan",
            "--start"},
           {"render " + quoted(file) + " -o " + quoted(temp_path(".mp4")) + " --end nan", "--end"},
           {"view " + quoted(file) + " --frame 1000 --frames 0 --screenshot " +
                quoted(temp_path(".png")),
            "--frame = 1000 is invalid: a recorded frame, 0 to "},
           {"view " + quoted(file) + " --frames 0 --screenshot ''", "--screenshot"}}) {
    const Result r = jelly(command);
    EXPECT_EQ(r.code, 2) << command << ": " << r.err;
    // A jelly built without the viewer (CI's sanitizer build) refuses render and view as such.
    if (r.err.find("this jelly was built without") != std::string::npos) continue;
    EXPECT_THAT(r.err, HasSubstr(field)) << command;
  }
}

// Issue 44, item 10: a fit whose residuals cannot be evaluated (ks 1e9 makes every rk4 replay
// of the drop diverge: Ceres' cost -1) exits 3 and writes no scene; before, it exited 0 with
// "cost -1, NOT converged", or crashed (SIGSEGV) computing the covariance.
TEST(Silent, AFitWhoseResidualsCannotBeEvaluatedExitsThree) {
  const std::string file = temp_path(".h5");
  Result r = jelly("run " + quoted(scene("drop_coulomb.json")) +
                   " --set cube.n=3 --set 'cube.origin=[-1,0.3,-1]' --set integrator.name='\"rk4\"'"
                   " --set output_interval=0.01 --duration 0.5 -q -o " +
                   quoted(file));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string fitted = temp_path(".json");
  for (const std::string covariance : {"", " --no-covariance"}) {
    r = jelly("fit " + quoted(file) + " --initial ks=1e9 --write-scene " + quoted(fitted) +
              covariance);
    EXPECT_EQ(r.code, 3) << covariance << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr("error: the fit's residuals could not be evaluated"));
    EXPECT_FALSE(exists(fitted));
  }
}

// Issue 44, item 11: a size so small or a position so far out that the particles' distances are
// lost in double precision is named by the body (and its size fields), not as
// springs[0].rest_length, a field no scene has.
TEST(Silent, ABodyWhoseParticlesCollapseIsNamed) {
  for (const std::string set : {"cube.edge_length=1e-300", "cube.origin=[1e308,0,0]"}) {
    const Result r = jelly("run " + kSmallSlope + " --set '" + set + "' --duration 0.01 -q");
    EXPECT_EQ(r.code, 2) << set;
    EXPECT_THAT(r.err, HasSubstr("error: bodies[0] (the cube \"jelly\") = particles ")) << set;
    EXPECT_THAT(r.err, HasSubstr("edge_length")) << set;
    EXPECT_THAT(r.err, Not(HasSubstr("rest_length"))) << set;
  }
}

// Issue 44, item 11: an unknown command is named, with the commands there are (CLI11 said "A
// subcommand is required").
TEST(Silent, AnUnknownCommandIsNamed) {
  const Result r = jelly("simulate " + kSmallSlope);
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("error: unknown command 'simulate'; the commands are run, "));
}

// ---- Hangs ----

TEST(Hangs, ACharacterDeviceAsTheSceneExitsTwo) {
  const Result r = jelly("run /dev/zero");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: cannot read the scene file '/dev/zero': it is a character device, "
            "not a file\n");
}

TEST(Hangs, APipeAsAnInputFileExitsTwo) {
  const std::string fifo = temp_path(".h5");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& command :
       {"info " + quoted(fifo), "xdmf " + quoted(fifo), "fit " + quoted(fifo),
        "run " + kSmallSlope + " --restart " + quoted(fifo)}) {
    const Result r = jelly(command);
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_THAT(r.err, HasSubstr("it is a pipe, not a file")) << command;
  }
  const std::string msh = temp_path(".msh");
  ASSERT_EQ(mkfifo(msh.c_str(), 0600), 0);
  const Result r =
      jelly("run " +
            quoted(write_scene(R"({"bodies": [{"kind": "tetmesh", "file": ")" + msh +
                               R"("}], "integrator": {"name": "rk4"}, "duration": 1})")) +
            " -q");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("bodies[0].file = \"" + msh + "\" is invalid: a regular file"));
}

// ---- Security ----

TEST(Security, AMeshFileOfGmshScriptRunsNothingAndExitsTwo) {
  const std::string touched = temp_path(".touched");
  const std::string msh = temp_path(".msh");
  std::ofstream(msh) << "SystemCall \"touch " << touched << "\";\n";
  const std::string scene = write_scene(R"({"bodies": [{"kind": "tetmesh", "file": ")" + msh +
                                        R"("}], "integrator": {"name": "rk4"}, "duration": 1})");
  const Result r = jelly("run " + quoted(scene) + " -q");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("found 'SystemCall' (a mesh file is data"));
  EXPECT_FALSE(exists(touched));
  // jelly mesh reads its surface with the mesh readers: a .msh is not handed to Gmsh.
  const Result m = jelly("mesh " + quoted(msh) + " -o " + quoted(temp_path(".msh")));
  EXPECT_EQ(m.code, 2);
  EXPECT_THAT(m.err, HasSubstr("a mesh file ending in .obj, .stl or .ply"));
  EXPECT_FALSE(exists(touched));
}

TEST(Hangs, AbsurdStepAndFrameCountsExitTwoBeforeTheRun) {
  Result r = jelly("run " + kSmallSlope + " --dt 1e-12");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: integrator.dt = 1e-12 is invalid: a step that is not lost "
                                "to rounding at t = 5 s"));
  r = jelly("run " + kSmallSlope + " --dt 1e-9");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: integrator.dt = 1e-09 is invalid: a step giving at most "
                                "1000000000 steps"));
  r = jelly("run " + kSmallSlope + " --set output_interval=1e-300");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: output_interval = 1e-300 is invalid"));
  r = jelly("run " + kSmallSlope + " --duration 1e300");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: integrator.dt = 0.001 is invalid: a step that is not lost "
                                "to rounding at t = 1e+300 s"));
}

TEST(Hangs, CheckpointsWithAbsurdTimesExitTwo) {
  const std::string file = temp_path(".h5");
  record(file);
  set_attribute(file, "/checkpoint", "t", -1e300);  // t + dt == t
  Result r = jelly("run " + kSmallSlope + " --duration 0.2 --restart " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: integrator.dt = 0.001 is invalid: a step that is not lost "
                                "to rounding at t = 1e+300 s"));
  record(file, " --overwrite");
  set_attribute(file, "/checkpoint", "next_output", -1e300);
  r = jelly("run " + kSmallSlope + " --duration 0.2 --restart " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("checkpoint next_output = -1.0000000000000001e+300 is invalid"));
}

// ---- Silent runs ----

TEST(SilentRuns, EmptyOptionValuesExitTwo) {
  for (const std::string option :
       {"-o", "--duration", "--dt", "--integrator", "--set", "--restart"}) {
    const Result r = jelly("run " + kSmallSlope + " " + option + " ''");
    EXPECT_EQ(r.code, 2) << option;
    EXPECT_THAT(r.err, HasSubstr(": an empty value")) << option;
  }
  const Result r = jelly("info ''");
  EXPECT_EQ(r.code, 2);
}

TEST(SilentRuns, ATimeStepLongerThanTheDurationExitsTwo) {
  const Result r = jelly("run " + kSmallSlope + " --dt 1 --duration 0.3");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: integrator.dt = 1 is invalid: larger than twice the duration (0.3 s): "
            "the run would take no step\n");
}

TEST(SilentRuns, DuplicateJsonKeysExitTwo) {
  const std::string file =
      write_scene(R"({"integrator": {"name": "rk4"}, "duration": 1, "cube": {"n": 3, "n": 4}})");
  const Result r = jelly("run " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("the key \"n\" appears twice in cube"));
}

TEST(SilentRuns, ARestartOfAnotherSceneExitsTwo) {
  const std::string file = temp_path(".h5");
  record(file);
  const std::string restart = " --duration 0.2 -q --restart " + quoted(file);
  Result r = jelly("run " + kSmallSlope + restart + " --set springs.structural.ks=2400");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err,
              HasSubstr("its run had bodies[0].springs.structural.ks = 1400.0, this scene has "
                        "2400.0: a restart continues the same run"));
  r = jelly("run " + kSmallSlope + restart + " --set gravity=[0,-1,0]");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("its run had gravity[1] = -9.8, this scene has -1.0"));
  r = jelly("run " + kSmallSlope + restart + " --set terrains=[]");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("its run had terrains = [{"));
  // What may change: the duration (that is the point), the output interval, the description.
  r = jelly("run " + kSmallSlope + restart + " --set output_interval=0.01 --set description=x");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, StartsWith("jelly run: completed at t = 0.2 s after 100 steps"));
}

TEST(SilentRuns, ARestartAtOrAfterTheDurationExitsTwo) {
  const std::string file = temp_path(".h5");
  record(file);
  const Result r = jelly("run " + kSmallSlope + " --duration 0.1 --restart " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: duration = 0.1 is invalid: the run would take no step: "
                                "it starts at t = 0.1"));
}

// ---- Wrong exit codes and messages ----

TEST(ExitCodes, ANumberBeyondADoubleExitsTwo) {
  const Result r = jelly("run " + kSmallSlope + " --set springs.shear.ks=1e999");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("number overflow parsing '1e999'"));
}

TEST(ExitCodes, ACubeBeyondMemoryExitsTwoWithTheEstimate) {
  const std::string s = "'" + scene("seed_slope.json") + "'";
  const Result r = jelly("run " + s + " --set cube.n=400");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: bodies = 64000000 particles is invalid: at most "
                                "max_particles = 2000000 (they would need about 100.7 GB of "
                                "memory with rk4"));
}

TEST(ExitCodes, AnUnwritableSidecarExitsTwoBeforeTheRun) {
  const std::string file = temp_path(".h5");
  const std::string sidecar = file.substr(0, file.size() - 3) + ".xdmf";
  ASSERT_EQ(mkdir(sidecar.c_str(), 0755), 0);
  const auto start = std::chrono::steady_clock::now();
  const Result r = jelly("run " + kSmallSlope + " --duration 2 -o " + quoted(file));
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr(sidecar + " is a directory"));
  EXPECT_EQ(r.out, "");  // no run, no summary
  EXPECT_FALSE(exists(file));
  rmdir(sidecar.c_str());
  (void)start;
}

TEST(ExitCodes, AFullDiskExitsOneWithASummaryAndAClearMessage) {
  // A file size limit (ulimit -f, with SIGXFSZ ignored) fails the writes as a full disk does.
  const std::string file = temp_path(".h5");
  const std::string command = "sh -c \"trap '' XFSZ; ulimit -f 256; exec '" +
                              std::string(JELLY_CLI) + "' run " + scene("seed_slope.json") +
                              " --set cube.n=4 --set output_interval=0 --duration 1 -o '" + file +
                              "'\"";
  const std::string out = temp_path(".out"), err = temp_path(".err");
  const int status = std::system((command + " >'" + out + "' 2>'" + err + "'").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << read_file(err);
  const std::string stdout_text = read_file(out), stderr_text = read_file(err);
  EXPECT_THAT(stdout_text, StartsWith("jelly run: stopped at t = "));
  EXPECT_THAT(stdout_text, HasSubstr("the recording failed\n  integrator      rk4"));
  EXPECT_THAT(stderr_text, StartsWith("error: writing " + file + " failed: "));
  EXPECT_THAT(stderr_text, HasSubstr("File too large"));
  // What was flushed may be readable or not (HDF5 is not crash consistent): the message says.
  EXPECT_THAT(stderr_text, AnyOf(HasSubstr("(it keeps "), HasSubstr("(it cannot be read back: ")));
  EXPECT_THAT(stderr_text, Not(HasSubstr("infinite loop")));
  EXPECT_EQ(std::count(stderr_text.begin(), stderr_text.end(), '\n'), 1) << stderr_text;
}

// ---- Silent numerical failure ----

// The number after `key = ` in the summary's statistics line, or -1.
long statistic(const std::string& summary, const std::string& key) {
  const std::size_t at = summary.find(key + " = ");
  return at == std::string::npos ? -1 : std::stol(summary.substr(at + key.size() + 3));
}

// The slope (coulomb contact, inside the solve) at 1/60 s with Newton cut to 5 iterations:
// Newton ends above its tolerance on some of the 180 steps (32 when this was written; issue 16
// found 111 of 180 on the seed slope, which now diverges with Newton at 1/60 s).
const std::string kShortNewton =
    "run " + kSmallSlope +
    " --integrator implicit_euler --dt 0.0166667 --duration 3 -q"
    " --set integrator.options.newton_iterations=5 --set terrains[0].contact.model=coulomb";

TEST(SilentNumericalFailure, NewtonStoppedAboveItsToleranceIsAWarningCountedInTheSummary) {
  const std::string file = temp_path(".h5");
  const Result r = jelly(kShortNewton + " -o " + quoted(file));
  ASSERT_EQ(r.code, 0) << r.err;
  const long missed = statistic(r.out, "newton_not_converged");
  ASSERT_GT(missed, 0) << r.out;
  const std::string what =
      "implicit_euler: Newton did not converge within integrator.options.newton_iterations = 5 "
      "(newton_tolerance = ";
  const std::string count = "on " + std::to_string(missed) + " of 180 steps";
  EXPECT_THAT(r.out, StartsWith("jelly run: completed_with_warnings at t = "));
  EXPECT_THAT(r.out, HasSubstr(what));
  EXPECT_THAT(r.out, HasSubstr(count));
  EXPECT_THAT(r.err, AllOf(StartsWith("warning: " + what), HasSubstr(count),
                           HasSubstr("(--strict makes this an error)")));
  // The recording says so too (run_status, run_reason).
  const Result info = jelly("info " + quoted(file));
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("status:        completed_with_warnings at t = "));
  EXPECT_THAT(info.out, HasSubstr(count));
}

TEST(SilentNumericalFailure, StrictMakesAMissedToleranceExitThree) {
  const Result r = jelly(kShortNewton + " --strict");
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_THAT(r.out, StartsWith("jelly run: completed_with_warnings"));
  EXPECT_THAT(r.err, StartsWith("error: the run missed its solver's tolerance (--strict): "
                                "implicit_euler: Newton did not converge"));
}

TEST(SilentNumericalFailure, ARunThatMetItsToleranceIsCompletedEvenWithStrict) {
  // Free fall above the slope (0.2 s): Newton converges in every step.
  const Result r = jelly("run " + kSmallSlope +
                         " --integrator implicit_euler --dt 0.0166667 --duration 0.2 -q --strict"
                         " --set integrator.options.newton_iterations=20"
                         " --set terrains[0].contact.model=coulomb");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(statistic(r.out, "newton_not_converged"), 0) << r.out;
  EXPECT_THAT(r.out, StartsWith("jelly run: completed at t = "));
  EXPECT_EQ(r.err, "");
}

TEST(SilentNumericalFailure, ProjectiveDynamicsAboveItsToleranceIsAWarning) {
  const Result r = jelly("run " + kSmallSlope +
                         " --integrator projective_dynamics --dt 0.0166667 --duration 0.5 -q"
                         " --set integrator.options.iterations=2"
                         " --set integrator.options.tolerance=1e-12");
  ASSERT_EQ(r.code, 0) << r.err;
  const long missed = statistic(r.out, "not_converged");
  ASSERT_GT(missed, 0) << r.out;
  EXPECT_THAT(r.out, StartsWith("jelly run: completed_with_warnings"));
  EXPECT_THAT(r.err, HasSubstr("projective_dynamics: the residual stayed above "
                               "integrator.options.tolerance = 1e-12 after iterations = 2 on " +
                               std::to_string(missed) + " of 30 steps"));
}

}  // namespace
}  // namespace jelly
