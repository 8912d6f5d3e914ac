// The XDMF sidecar (io/h5_recorder.hpp): every DataItem names a whole dataset of the recording, the
// per-frame views read as the recorded frames, the derived arrays are what they claim, and the
// sidecar is the same whether written at the end of a run, in several runs or from the file
// alone. (That ParaView's readers open it: the ctest jelly_paraview, tests/io/paraview_test.py.)
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/triangle_mesh.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/terrain.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A dataset of the file read as doubles (any numeric type), with its dimensions.
std::vector<double> read(hid_t file, const std::string& path,
                         std::vector<hsize_t>* dims = nullptr) {
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << path;
  if (d < 0) return {};
  const hid_t s = H5Dget_space(d);
  std::vector<hsize_t> shape(H5Sget_simple_extent_ndims(s));
  H5Sget_simple_extent_dims(s, shape.data(), nullptr);
  hsize_t size = 1;
  for (hsize_t n : shape) size *= n;
  std::vector<double> values(size);
  EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0) << path;
  H5Sclose(s);
  H5Dclose(d);
  if (dims) *dims = shape;
  return values;
}

// Records `seconds` of a small cube on the slope (or the seed elevator) to `path`.
void record(const std::string& path, RecorderOptions options = {}, bool elevator = false,
            std::vector<double> stops = {0.5}) {
  const Model cube = build_cube(testing::small_cube(3, 1.0, Vec3(-0.5, 1.2, -0.5)));
  Simulator sim = elevator ? testing::make_sim(cube, rest_state(cube), "rk4", 1e-3, 0.02)
                           : testing::slope_sim();
  if (elevator) sim.add_terrain(std::make_unique<Elevator>());
  H5Recorder recorder(path, sim, options);
  sim.add_observer(recorder);
  for (double t : stops) ASSERT_TRUE(sim.run_until(t).ok());
}

struct Item {
  std::string dims, path;
};

// Every DataItem of the sidecar that names a dataset ("run.h5:/path").
std::vector<Item> hdf_items(const std::string& text) {
  static const std::regex item(
      R"re(<DataItem Dimensions="([0-9 ]+)" NumberType="\w+" Precision="\d" Format="HDF">([^<:]+):([^<]+)</DataItem>)re");
  std::vector<Item> items;
  for (std::sregex_iterator it(text.begin(), text.end(), item), end; it != end; ++it) {
    EXPECT_EQ((*it)[2], "run.h5");
    items.push_back({(*it)[1], (*it)[3]});
  }
  return items;
}

TEST(Xdmf, EveryDataItemNamesAWholeDatasetOfTheRecording) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  record(path);
  const std::string text = read_text(dir.file("run.xdmf"));
  // No HyperSlab or Function items: VTK's Xdmf3 readers read none of them.
  EXPECT_EQ(text.find("HyperSlab"), std::string::npos);
  EXPECT_EQ(text.find("Function"), std::string::npos);
  // One temporal collection per body, per body's surface and per terrain, 26 frames each.
  EXPECT_NE(text.find(R"(<Grid Name="jelly" GridType="Collection" CollectionType="Temporal">)"),
            std::string::npos);
  EXPECT_NE(
      text.find(R"(<Grid Name="jelly surface" GridType="Collection" CollectionType="Temporal">)"),
      std::string::npos);
  EXPECT_NE(text.find(R"(<Grid Name="0_plane" GridType="Collection" CollectionType="Temporal">)"),
            std::string::npos);
  size_t times = 0;
  for (size_t at = text.find("<Time "); at != std::string::npos; at = text.find("<Time ", at + 1))
    ++times;
  EXPECT_EQ(times, 3u * 26);

  const std::vector<Item> items = hdf_items(text);
  ASSERT_GT(items.size(), 26u * 10);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  size_t checked = 0;
  for (const Item& item : items) {
    if (checked++ % 7 != 0 && item.path.find("/25") == std::string::npos) continue;  // a sample
    std::vector<hsize_t> dims;
    read(file, item.path, &dims);
    std::string shape;
    for (hsize_t d : dims) shape += (shape.empty() ? "" : " ") + std::to_string(d);
    EXPECT_EQ(shape, item.dims) << item.path;
  }
  H5Fclose(file);

  if (!testing::python_has("xml.etree.ElementTree")) GTEST_SKIP() << "no /usr/bin/python3";
  const std::string parse =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; "
      "E.parse(sys.argv[1])\" " +
      dir.file("run.xdmf");
  EXPECT_EQ(std::system(parse.c_str()), 0);
}

TEST(Xdmf, ViewsAreTheRecordedFramesAndDerivedArraysWhatTheyClaim) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  record(path);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  std::vector<hsize_t> dims;
  const std::vector<double> x = read(file, "/particles/jelly/position/value", &dims);
  const std::vector<double> v = read(file, "/particles/jelly/velocity/value");
  ASSERT_EQ(dims.size(), 3u);
  const hsize_t frames = dims[0], n = dims[1];
  const std::vector<double> ends = read(file, "/connectivity/springs");
  const std::vector<double> rest = read(file, "/connectivity/rest_length");
  const hsize_t m = rest.size();
  for (hsize_t f : {hsize_t{0}, hsize_t{13}, frames - 1}) {
    const std::string k = std::to_string(f);
    const std::vector<double> xf(x.begin() + 3 * n * f, x.begin() + 3 * n * (f + 1));
    const std::vector<double> vf(v.begin() + 3 * n * f, v.begin() + 3 * n * (f + 1));
    EXPECT_EQ(read(file, "/xdmf/particles/jelly/frame/position/" + k), xf) << f;
    EXPECT_EQ(read(file, "/xdmf/particles/jelly/frame/velocity/" + k), vf) << f;
    const std::vector<double> speed = read(file, "/xdmf/particles/jelly/frame/speed/" + k);
    ASSERT_EQ(speed.size(), n);
    for (hsize_t i = 0; i < n; ++i) {
      const double s = std::sqrt(vf[3 * i] * vf[3 * i] + vf[3 * i + 1] * vf[3 * i + 1] +
                                 vf[3 * i + 2] * vf[3 * i + 2]);
      EXPECT_NEAR(speed[i], s, 1e-6 * (1 + s)) << "frame " << f << " particle " << i;
    }
    const std::vector<double> strain = read(file, "/xdmf/particles/jelly/frame/strain/" + k);
    ASSERT_EQ(strain.size(), m);
    for (hsize_t s = 0; s < m; ++s) {
      const double* a = xf.data() + 3 * static_cast<hsize_t>(ends[2 * s]);
      const double* b = xf.data() + 3 * static_cast<hsize_t>(ends[2 * s + 1]);
      const double length =
          std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
      EXPECT_NEAR(strain[s], length / rest[s] - 1, 2e-5) << "frame " << f << " spring " << s;
    }
  }
  // The plane: a quad (2 triangles) in the plane, not moving.
  std::vector<hsize_t> quad;
  const std::vector<double> corners = read(file, "/xdmf/terrain/0_plane/vertices", &quad);
  EXPECT_EQ(quad, (std::vector<hsize_t>{4, 3}));
  const Vec3 normal(std::sin(20 * M_PI / 180), std::cos(20 * M_PI / 180), 0);
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(normal.dot(Vec3(corners[3 * c], corners[3 * c + 1], corners[3 * c + 2])), 0, 1e-12);
  }
  EXPECT_EQ(read(file, "/xdmf/terrain/0_plane/triangles").size(), 6u);
  H5Fclose(file);
}

TEST(Xdmf, TheElevatorIsABoxAtItsRecordedHeight) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  record(path, {}, true);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  std::vector<hsize_t> dims;
  const std::vector<double> platform = read(file, "/terrain/0_elevator/position/value", &dims);
  const hsize_t frames = dims[0];
  ASSERT_GT(platform[3 * (frames - 1) + 1], platform[1] + 0.1);  // it moved
  for (hsize_t f : {hsize_t{0}, frames / 2, frames - 1}) {
    std::vector<hsize_t> box;
    const std::vector<double> corners =
        read(file, "/xdmf/terrain/0_elevator/frame/position/" + std::to_string(f), &box);
    ASSERT_EQ(box, (std::vector<hsize_t>{8, 3}));
    double top = -1e300, bottom = 1e300;
    for (int c = 0; c < 8; ++c) {
      top = std::max(top, corners[3 * c + 1]);
      bottom = std::min(bottom, corners[3 * c + 1]);
      EXPECT_NEAR(std::abs(corners[3 * c]), 2.5, 1e-12);  // the 5 x 5 m platform
    }
    EXPECT_NEAR(top, platform[3 * f + 1], 1e-12) << f;
    EXPECT_NEAR(top - bottom, ElevatorSpec{}.thickness, 1e-12);
  }
  EXPECT_EQ(read(file, "/xdmf/terrain/0_elevator/triangles").size(), 36u);
  // The recorder records the elevator's render mesh (Terrain::render_mesh()), which this is.
  std::vector<hsize_t> mesh_dims;
  read(file, "/terrain/0_elevator/mesh/vertices", &mesh_dims);
  EXPECT_EQ(mesh_dims, (std::vector<hsize_t>{8, 3}));
  read(file, "/terrain/0_elevator/mesh/triangles", &mesh_dims);
  EXPECT_EQ(mesh_dims, (std::vector<hsize_t>{12, 3}));
  // Its speed: 3 m/s^2 from rest, about 3 t.
  const std::vector<double> speed =
      read(file, "/xdmf/terrain/0_elevator/frame/speed/" + std::to_string(frames - 1));
  EXPECT_NEAR(speed[0], 3 * 0.5, 0.05);
  const std::vector<double> last =
      read(file, "/xdmf/terrain/0_elevator/frame/position/" + std::to_string(frames - 1));
  H5Fclose(file);

  // A recording made before the meshes were recorded: the box comes from the elevator's size.
  const std::string old = dir.file("old.h5");
  std::filesystem::copy_file(path, old);
  const hid_t f = H5Fopen(old.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(H5Ldelete(f, "/terrain/0_elevator/mesh", H5P_DEFAULT), 0);
  ASSERT_GE(H5Ldelete(f, "/xdmf", H5P_DEFAULT), 0);
  H5Fclose(f);
  write_xdmf_for_recording(old);
  const hid_t g = H5Fopen(old.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  std::vector<double> again =
      read(g, "/xdmf/terrain/0_elevator/frame/position/" + std::to_string(frames - 1));
  H5Fclose(g);
  // The same corners, maybe in another order.
  auto sorted = [](std::vector<double> xyz) {
    std::vector<std::array<double, 3>> corners;
    for (size_t k = 0; k + 2 < xyz.size(); k += 3)
      corners.push_back({xyz[k], xyz[k + 1], xyz[k + 2]});
    std::sort(corners.begin(), corners.end());
    return corners;
  };
  const auto a = sorted(last), b = sorted(again);
  ASSERT_EQ(a.size(), b.size());
  for (size_t c = 0; c < a.size(); ++c) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[c][k], b[c][k], 1e-12);
  }
}

// The sidecar after a run in three parts, or written from the file alone after a run without
// one, is the one a single run writes.
TEST(Xdmf, SameSidecarInPartsOrFromTheFileAlone) {
  TempDir whole, parts, later;
  record(whole.file("run.h5"));
  record(parts.file("run.h5"), {}, false, {0.1, 0.3, 0.5});
  RecorderOptions no_sidecar;
  no_sidecar.write_xdmf = false;
  record(later.file("run.h5"), no_sidecar);
  EXPECT_FALSE(std::filesystem::exists(later.file("run.xdmf")));
  EXPECT_EQ(write_xdmf_for_recording(later.file("run.h5")), later.file("run.xdmf"));
  const std::string text = read_text(whole.file("run.xdmf"));
  EXPECT_EQ(read_text(parts.file("run.xdmf")), text);
  EXPECT_EQ(read_text(later.file("run.xdmf")), text);
  // And once more changes nothing.
  write_xdmf_for_recording(later.file("run.h5"));
  EXPECT_EQ(read_text(later.file("run.xdmf")), text);

  // Equal, but for strain's rounding (scale-offset rounds relative to each chunk's minimum).
  const hid_t a = H5Fopen(whole.file("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t b = H5Fopen(parts.file("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  for (const char* dataset :
       {"/xdmf/particles/jelly/speed", "/xdmf/particles/jelly/frame/position/25",
        "/xdmf/particles/jelly/surface/speed", "/xdmf/particles/jelly/surface/frame/position/25"}) {
    EXPECT_EQ(read(a, dataset), read(b, dataset)) << dataset;
  }
  const std::vector<double> strain_a = read(a, "/xdmf/particles/jelly/strain");
  const std::vector<double> strain_b = read(b, "/xdmf/particles/jelly/strain");
  ASSERT_EQ(strain_a.size(), strain_b.size());
  for (size_t i = 0; i < strain_a.size(); ++i) ASSERT_NEAR(strain_a[i], strain_b[i], 2e-5) << i;
  H5Fclose(a);
  H5Fclose(b);
}

// Several bodies: each is a block of particles and springs followed by a block of its render
// surface, whose per-frame vertices are the recorded ones and whose speed is that of the
// vertices (the weighted sums of the particle velocities).
TEST(Xdmf, EachBodyAndItsSurfaceAreBlocks) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  const Scene scene = parse_scene(R"({
    "bodies": [
      {"kind": "cube", "name": "jelly", "n": 3, "edge_length": 0.6, "origin": [-1.5, 0.5, -0.3]},
      {"kind": "cloth", "name": "flag", "nu": 5, "nv": 4, "size_u": 1, "size_v": 0.8,
       "position": [0, 1.5, 0], "particle_mass": 0.5, "pins": [{"group": "corner_00"}]}
    ],
    "terrains": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                  "contact": {"model": "coulomb", "restitution": 0.4, "friction": 0.3}}],
    "integrator": {"name": "rk4", "dt": 0.001}, "duration": 1, "output_interval": 0.02})");
  Model model;
  {
    Simulator sim = make_simulator(scene);
    model = sim.model();
    H5Recorder recorder(path, sim, {});
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(0.3).ok());
  }
  ASSERT_EQ(model.bodies.size(), 2u);
  const std::string text = read_text(dir.file("run.xdmf"));
  std::vector<std::string> blocks;
  static const std::regex collection(R"re(<Grid Name="([^"]+)" GridType="Collection")re");
  for (std::sregex_iterator it(text.begin(), text.end(), collection), end; it != end; ++it)
    blocks.push_back((*it)[1]);
  EXPECT_EQ(blocks, (std::vector<std::string>{"jelly", "jelly surface", "flag", "flag surface",
                                              "0_plane"}));
  EXPECT_NE(text.find(R"(<Topology TopologyType="Triangle" NumberOfElements=")" +
                      std::to_string(model.bodies[1].surface.num_triangles()) + "\">"),
            std::string::npos);

  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  for (const Body& body : model.bodies) {
    const std::string g = "/particles/" + body.name, x = "/xdmf" + g + "/surface";
    std::vector<hsize_t> dims;
    const std::vector<double> recorded = read(file, g + "/surface/position/value", &dims);
    const std::vector<double> v = read(file, g + "/velocity/value");
    const hsize_t frames = dims.at(0), V = dims.at(1), N = body.num_particles;
    ASSERT_EQ(frames, 16u);
    ASSERT_EQ(V, static_cast<hsize_t>(body.surface.num_vertices()));
    for (hsize_t f : {hsize_t{0}, hsize_t{7}, frames - 1}) {
      const std::string k = std::to_string(f);
      EXPECT_EQ(
          read(file, x + "/frame/position/" + k),
          std::vector<double>(recorded.begin() + 3 * V * f, recorded.begin() + 3 * V * (f + 1)))
          << body.name << " frame " << f;
      // The vertex velocities from the body's particle velocities (global indices).
      VecX vf = VecX::Zero(3 * model.num_particles());
      for (hsize_t i = 0; i < 3 * N; ++i) vf[3 * body.first_particle + i] = v[3 * N * f + i];
      const std::vector<double> speed = read(file, x + "/frame/speed/" + k);
      ASSERT_EQ(speed.size(), V);
      for (hsize_t i = 0; i < V; ++i) {
        const double s = body.surface.vertex(vf, static_cast<int>(i)).norm();
        EXPECT_NEAR(speed[i], s, 1e-6 * (1 + s)) << body.name << " frame " << f << " vertex " << i;
      }
      if (f == frames - 1) {
        EXPECT_GT(*std::max_element(speed.begin(), speed.end()), 0.5);
      }
    }
  }
  H5Fclose(file);
}

// An obstacle turned, spinning and moving: its mesh at every frame is where Terrain::pose(t)
// puts it (the recorder records the rotation beside the position), its speed the rigid
// motion's at each vertex.
TEST(Xdmf, ASpinningObstacleIsWhereItsPosePutsIt) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  const Scene scene = parse_scene(R"({
    "bodies": [{"kind": "cube", "name": "jelly", "n": 3, "edge_length": 0.4,
                "origin": [-0.2, 1.5, -0.2]}],
    "terrains": [
      {"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
      {"kind": "box", "center": [0, 0.5, 0], "size": [2, 0.2, 1], "rotation_degrees": [0, 30, 10],
       "angular_velocity_degrees": [0, 90, 0],
       "motion": {"kind": "oscillation", "amplitude": [0.3, 0, 0], "frequency": 1}}],
    "integrator": {"name": "rk4", "dt": 0.001}, "duration": 1, "output_interval": 0.02})");
  Simulator sim = make_simulator(scene);
  {
    H5Recorder recorder(path, sim, {});
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(0.4).ok());
  }
  ASSERT_EQ(sim.terrains().size(), 2u);
  const Terrain& box = *sim.terrains()[1];
  const TriangleMesh mesh = box.render_mesh();
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  std::vector<hsize_t> dims;
  const std::vector<double> time = read(file, "/terrain/1_box/position/time", &dims);
  const hsize_t frames = dims.at(0);
  ASSERT_EQ(frames, 21u);
  read(file, "/terrain/1_box/rotation/value", &dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{frames, 3, 3}));
  const Vec3 omega(0, M_PI / 2, 0);
  for (hsize_t f : {hsize_t{0}, hsize_t{7}, frames - 1}) {
    const std::string k = std::to_string(f);
    const std::vector<double> xyz = read(file, "/xdmf/terrain/1_box/frame/position/" + k, &dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{static_cast<hsize_t>(mesh.num_vertices()), 3}));
    const std::vector<double> speed = read(file, "/xdmf/terrain/1_box/frame/speed/" + k);
    const Eigen::Isometry3d pose = box.pose(time[f]);
    // The speed is a difference over one frame (backward, forward at frame 0): the rigid
    // motion's speed at the middle of that frame, to second order.
    const double tm = f > 0 ? 0.5 * (time[f - 1] + time[f]) : 0.5 * (time[0] + time[1]);
    const Eigen::Isometry3d middle = box.pose(tm);
    const Vec3 centre_velocity = (box.position(tm + 1e-6) - box.position(tm - 1e-6)) / 2e-6;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const Vec3 want = pose * mesh.vertices[v];
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(xyz[3 * v + c], want[c], 1e-12) << f << " " << v;
      const double rigid =
          (centre_velocity + omega.cross(middle * mesh.vertices[v] - middle.translation())).norm();
      EXPECT_NEAR(speed[v], rigid, 0.01 * rigid + 1e-3) << "frame " << f << " vertex " << v;
    }
  }
  H5Fclose(file);
}

TEST(Xdmf, WithoutStrain) {
  TempDir dir;
  RecorderOptions options;
  options.xdmf.strain = false;
  record(dir.file("run.h5"), options);
  const std::string text = read_text(dir.file("run.xdmf"));
  EXPECT_EQ(text.find("strain"), std::string::npos);
  EXPECT_NE(text.find("Name=\"speed\""), std::string::npos);
  const hid_t file = H5Fopen(dir.file("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_EQ(H5Lexists(file, "/xdmf/particles/jelly/strain", H5P_DEFAULT), 0);
  H5Fclose(file);
}

double double_attribute(hid_t file, const char* object, const char* name, int index = 0) {
  const hid_t a = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << object << " " << name;
  if (a < 0) return NAN;
  const hid_t space = H5Aget_space(a);
  std::vector<double> values(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
  H5Sclose(space);
  EXPECT_GE(H5Aread(a, H5T_NATIVE_DOUBLE, values.data()), 0);
  H5Aclose(a);
  return values.at(static_cast<size_t>(index));
}

// Every <Time> is k x output_interval to 17 digits (not the recorded sum of steps), /xdmf holds
// the speed range over every frame, and the ParaView state written beside it carries that range
// and the bodies' box.
TEST(Xdmf, ExactTimesSpeedRangeAndParaviewState) {
  TempDir dir;
  const std::string path = dir.file("run.h5");
  record(path);
  const std::string text = read_text(dir.file("run.xdmf"));
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const double interval = double_attribute(file, "/parameters", "output_interval");
  const double dt = double_attribute(file, "/parameters", "dt");
  ASSERT_GT(interval, 0);
  ASSERT_NEAR(std::remainder(interval, dt), 0, 1e-12);  // frames fall on multiples of both
  const std::vector<double> recorded = read(file, "/particles/jelly/position/time");
  const std::regex time(R"re(<Time Value="([^"]+)"/>)re");
  std::vector<std::string> times;
  for (std::sregex_iterator it(text.begin(), text.end(), time), end; it != end; ++it)
    times.push_back((*it)[1]);
  ASSERT_EQ(times.size(), 3 * recorded.size());  // the body, its surface, the plane
  int sums = 0;
  for (size_t g = 0; g < 3; ++g)
    for (size_t k = 0; k < recorded.size(); ++k) {
      char expected[40];
      std::snprintf(expected, sizeof expected, "%.17g", static_cast<double>(k) * interval);
      EXPECT_EQ(times[g * recorded.size() + k], expected) << "grid " << g << " frame " << k;
      sums += recorded[k] != static_cast<double>(k) * interval;
    }
  std::printf("%d of %zu recorded times differ from k x output_interval\n", sums / 3,
              recorded.size());

  double lo = 1e300, hi = -1e300;
  for (const char* speeds : {"/xdmf/particles/jelly/speed", "/xdmf/particles/jelly/surface/speed"})
    for (double s : read(file, speeds)) {
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
  EXPECT_EQ(double_attribute(file, "/xdmf", "speed_range", 0), lo);
  EXPECT_EQ(double_attribute(file, "/xdmf", "speed_range", 1), hi);
  EXPECT_EQ(lo, 0);  // the cube starts at rest
  EXPECT_GT(hi, 1);  // and slides
  double fastest = 0;
  const std::vector<double> v = read(file, "/particles/jelly/velocity/value");
  for (size_t i = 0; i + 2 < v.size(); i += 3)
    fastest = std::max(fastest, std::sqrt(v[i] * v[i] + v[i + 1] * v[i + 1] + v[i + 2] * v[i + 2]));
  EXPECT_NEAR(hi, fastest, 1e-6 * fastest);
  std::array<double, 6> bounds{};
  for (int c = 0; c < 6; ++c) bounds[c] = double_attribute(file, "/xdmf", "bounds", c);
  H5Fclose(file);

  const std::string state = write_paraview_state(path);
  EXPECT_EQ(state, dir.file("run.paraview.py"));
  const std::string script = read_text(state);
  char line[200];
  std::snprintf(line, sizeof line, "SPEED_RANGE = [%.17g, %.17g]", lo, hi);
  EXPECT_NE(script.find(line), std::string::npos) << script;
  std::snprintf(line, sizeof line, "BOUNDS = [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g]", bounds[0],
                bounds[1], bounds[2], bounds[3], bounds[4], bounds[5]);
  EXPECT_NE(script.find(line), std::string::npos) << script;
  EXPECT_NE(script.find("SIDECAR = \"run.xdmf\""), std::string::npos);
  if (testing::python_has("ast")) {
    const std::string parse =
        "/usr/bin/python3 -c \"import ast, sys; ast.parse(open(sys.argv[1]).read())\" '" + state +
        "'";
    EXPECT_EQ(std::system(parse.c_str()), 0);
  }

  // Without sidecar data there is nothing to set the state from.
  RecorderOptions none;
  none.write_xdmf = false;
  record(dir.file("bare.h5"), none);
  EXPECT_THROW(write_paraview_state(dir.file("bare.h5")), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("bare.paraview.py")));
}

TEST(Xdmf, ErrorsNameTheFileOrOption) {
  TempDir dir;
  try {
    write_xdmf_for_recording(dir.file("missing.h5"));
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.h5"), std::string::npos) << e.what();
  }
  XdmfOptions options;
  options.compression_level = 10;
  EXPECT_THROW(options.validate(), InputError);
  RecorderOptions recorder;
  recorder.xdmf.compression_level = -1;
  EXPECT_THROW(recorder.validate(), InputError);
}

}  // namespace
}  // namespace jelly
