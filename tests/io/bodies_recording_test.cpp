// Recordings of scenes with several bodies: one /particles/<name>/ group per body with its
// surface, read back into the same bodies, and restarts that continue bit for bit.
#include <gtest/gtest.h>

#include <vector>

#include <jelly/core/detail/json.hpp>
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/detail/h5.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>

#include "io/io_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

// A cube falling onto a floor beside a cloth pinned at a corner driven up and down, and a box.
Scene three_bodies(const std::string& integrator, Real dt) {
  return parse_scene(R"({
    "bodies": [
      {"kind": "cube", "name": "jelly", "n": 3, "edge_length": 0.6, "origin": [-1.5, 0.5, -0.3]},
      {"kind": "cloth", "name": "flag", "nu": 5, "nv": 4, "size_u": 1, "size_v": 0.8,
       "position": [0, 1.5, 0], "particle_mass": 0.5,
       "pins": [{"group": "corner_00", "path": {"kind": "oscillation", "amplitude": [0, 0.2, 0],
                                                "frequency": 1}},
                {"group": "corner_10"}]},
      {"kind": "box", "name": "brick", "nx": 4, "ny": 2, "nz": 2, "size": [0.6, 0.2, 0.2],
       "position": [1.5, 0.4, 0]}
    ],
    "terrains": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                  "contact": {"model": "coulomb", "restitution": 0.4, "friction": 0.3}}],
    "integrator": {"name": ")" +
                     integrator + R"(", "dt": )" + std::to_string(dt) + R"(},
    "duration": 1, "output_interval": 0.02})");
}

struct CollectedFrames {
  std::vector<Real> t;
  std::vector<VecX> x, v;
};

auto collect(CollectedFrames& out) {
  return testing::Probe([&out](const Simulator& s) {
    out.t.push_back(s.state().t);
    out.x.push_back(s.state().x);
    out.v.push_back(s.state().v);
  });
}

// Each body has its group: its particles' slice of every frame, its masses and its surface,
// whose recorded vertex positions are the surface evaluated at the frame's particles.
TEST(BodiesRecording, EachBodyItsGroupAndSurface) {
  TempDir dir;
  const std::string path = dir.file("bodies.h5");
  const Scene scene = three_bodies("rk4", 1e-3);
  CollectedFrames frames;
  Model model;
  {
    Simulator sim = make_simulator(scene);
    model = sim.model();
    RecorderOptions options;
    options.scene_json = scene_to_json(scene);
    H5Recorder recorder(path, sim, options);
    auto probe = collect(frames);
    sim.add_observer(recorder);
    sim.add_observer(probe);
    const RunReport report = sim.run_until(0.3);
    ASSERT_TRUE(report.ok()) << report.reason;
  }
  ASSERT_EQ(model.bodies.size(), 3u);
  const int T = static_cast<int>(frames.t.size());
  ASSERT_EQ(T, 16);

  const Recording r = read_recording(path);
  ASSERT_EQ(r.model.bodies.size(), 3u);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const Body& want = model.bodies[b];
    const Body& got = r.model.bodies[b];
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.kind, want.kind);
    EXPECT_EQ(got.first_particle, want.first_particle);
    EXPECT_EQ(got.num_particles, want.num_particles);
    EXPECT_EQ(got.first_spring, want.first_spring);
    EXPECT_EQ(got.num_springs, want.num_springs);
    EXPECT_EQ(got.radius, want.radius);
    EXPECT_EQ(got.surface.triangles, want.surface.triangles);
    EXPECT_EQ(got.surface.offsets, want.surface.offsets);
    EXPECT_EQ(got.surface.particles, want.surface.particles);
    EXPECT_EQ(got.surface.weights, want.surface.weights);
  }
  EXPECT_EQ(r.model.mass, model.mass);
  EXPECT_EQ(r.model.rest_position, model.rest_position);
  ASSERT_EQ(r.frames(), T);
  for (int f = 0; f < T; ++f) {
    EXPECT_EQ(r.position[f], frames.x[f]) << "frame " << f;
    EXPECT_EQ(r.velocity[f], frames.v[f]) << "frame " << f;
  }

  // The file itself: the body's slice and its surface vertices, frame by frame.
  h5::Handle file = h5::open_file(path);
  for (const Body& body : model.bodies) {
    const std::string g = "particles/" + body.name;
    EXPECT_EQ(h5::read_long_attribute(h5::open_group(file.get(), g).get(), "first_particle"),
              body.first_particle);
    const std::vector<double> x = h5::read_doubles(file.get(), g + "/position/value");
    const std::vector<double> s = h5::read_doubles(file.get(), g + "/surface/position/value");
    const int N = body.num_particles, V = body.surface.num_vertices();
    ASSERT_GT(V, 0) << body.name;
    ASSERT_EQ(x.size(), static_cast<size_t>(T) * N * 3) << body.name;
    ASSERT_EQ(s.size(), static_cast<size_t>(T) * V * 3) << body.name;
    for (int f = 0; f < T; f += 5) {
      for (int i = 0; i < N; ++i) {
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(x[(static_cast<size_t>(f) * N + i) * 3 + c],
                    frames.x[f][3 * (body.first_particle + i) + c]);
        }
      }
      for (int v = 0; v < V; ++v) {
        const Vec3 want = body.surface.vertex(frames.x[f], v);
        for (int c = 0; c < 3; ++c) {
          ASSERT_DOUBLE_EQ(s[(static_cast<size_t>(f) * V + v) * 3 + c], want[c])
              << body.name << " frame " << f << " vertex " << v;
        }
      }
    }
  }
  const std::string text = describe_recording(path);
  for (const char* name : {"jelly", "flag", "brick"}) {
    EXPECT_NE(text.find(name), std::string::npos) << text;
  }
}

class BodiesRestart : public ::testing::TestWithParam<std::pair<const char*, Real>> {};
INSTANTIATE_TEST_SUITE_P(Integrators, BodiesRestart,
                         ::testing::Values(std::make_pair("rk4", 1e-3),
                                           std::make_pair("implicit_euler", 1.0 / 60)),
                         [](const auto& p) { return std::string(p.param.first); });

// Stopped half way and continued from the recording's checkpoint in a fresh simulator of the
// same scene, three bodies with a driven pin and floor contact continue bit for bit.
TEST_P(BodiesRestart, ContinuesBitForBit) {
  TempDir dir;
  const Scene scene = three_bodies(GetParam().first, GetParam().second);
  CollectedFrames whole;
  {
    Simulator sim = make_simulator(scene);
    auto probe = collect(whole);
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(1.0).ok());
  }
  const size_t cut = whole.t.size() / 2;
  const std::string path = dir.file("half.h5");
  {
    Simulator sim = make_simulator(scene);
    RecorderOptions options;
    options.scene_json = scene_to_json(scene);
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(whole.t[cut]).ok());
  }
  Simulator sim = make_simulator(scene);
  restore(sim, read_checkpoint(path));
  CollectedFrames resumed;
  auto probe = collect(resumed);
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  ASSERT_EQ(resumed.t.size(), whole.t.size() - cut);
  for (size_t f = 0; f < resumed.t.size(); ++f) {
    ASSERT_EQ(resumed.t[f], whole.t[cut + f]);
    ASSERT_TRUE(resumed.x[f] == whole.x[cut + f]) << "positions differ at t = " << resumed.t[f];
    ASSERT_TRUE(resumed.v[f] == whole.v[cut + f]) << "velocities differ at t = " << resumed.t[f];
  }
}

}  // namespace
}  // namespace jelly
