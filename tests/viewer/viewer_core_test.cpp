// The viewer's parts that need no OpenGL: the bodies' surfaces (the adapter), the camera, the
// OBJ and PC2 exports read back, the live simulation's commands and frames, and `jelly view`
// without a display.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <thread>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/io/detail/export.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/viewer/camera.hpp>
#include <jelly/viewer/detail/exports.hpp>
#include <jelly/viewer/live_simulation.hpp>
#include <jelly/viewer/recording_view.hpp>
#include <jelly/viewer/scene_adapter.hpp>

#include "viewer/viewer_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

// The seed slope with a smaller cube, fast enough for tests.
Scene small_slope(int n = 4, const std::vector<std::string>& more = {}) {
  std::vector<std::string> overrides = {"cube.n=" + std::to_string(n), "cube.edge_length=1",
                                        "cube.origin=[-0.5,2,-0.5]"};
  overrides.insert(overrides.end(), more.begin(), more.end());
  return load_scene(JELLY_SCENES_DIR "/seed_slope.json", overrides);
}

// Records `seconds` of the small slope to `path`.
void record(const std::string& path, Real seconds, int n = 4) {
  const Scene scene = small_slope(n);
  Simulator sim = make_simulator(scene);
  RecorderOptions options;
  options.scene_json = scene_to_json(scene);
  options.write_xdmf = false;
  H5Recorder recorder(path, sim, options);
  sim.add_observer(recorder);
  ASSERT_TRUE(sim.run_until(seconds).ok());
}

// The lattice boundary is a closed surface of outward triangles enclosing the cube's volume.
TEST(BodySurface, CubeLatticeBoundaryIsClosedAndOutward) {
  for (const int n : {2, 3, 10}) {
    SCOPED_TRACE("n = " + std::to_string(n));
    CubeSpec spec;
    spec.n = n;
    spec.edge_length = 2;
    spec.origin = Vec3(1, 2, 3);
    const Model model = build_cube(spec);
    const std::vector<viewer::BodySurface> surfaces = viewer::body_surfaces(model);
    ASSERT_EQ(surfaces.size(), 1u);
    const viewer::BodySurface& s = surfaces[0];
    EXPECT_EQ(s.name, "jelly");
    EXPECT_EQ(s.num_particles, n * n * n);
    EXPECT_EQ(s.num_vertices(), n * n * n - (n - 2) * (n - 2) * (n - 2));
    EXPECT_EQ(s.triangles.size(), static_cast<size_t>(12 * (n - 1) * (n - 1)));
    const VecX& x = model.rest_position;
    // Every vertex is a boundary particle with weight 1.
    for (int v = 0; v < s.num_vertices(); ++v) {
      ASSERT_EQ(s.offsets[v + 1] - s.offsets[v], 1);
      EXPECT_EQ(s.weights[s.offsets[v]], 1.0);
      EXPECT_EQ(s.vertex(x, v), Vec3(particle(x, s.particles[s.offsets[v]])));
    }
    // Closed: every edge is shared by two triangles, once in each direction.
    std::map<std::pair<int, int>, int> edges;
    Real volume = 0;
    const Vec3 centre = spec.origin + Vec3::Constant(1.0);
    for (const auto& t : s.triangles) {
      for (int e = 0; e < 3; ++e) ++edges[{t[e], t[(e + 1) % 3]}];
      const Vec3 a = s.vertex(x, t[0]), b = s.vertex(x, t[1]), c = s.vertex(x, t[2]);
      const Vec3 normal = (b - a).cross(c - a);
      EXPECT_GT(normal.dot((a + b + c) / 3 - centre), 0);  // outwards
      volume += a.dot(b.cross(c)) / 6;
    }
    for (const auto& [edge, count] : edges) {
      EXPECT_EQ(count, 1);
      EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
    }
    EXPECT_NEAR(volume, 8.0, 1e-9);
  }
}

// A recording's bodies: from its scene when the file holds none; without a scene, all its
// particles as one body, a cube's lattice boundary when there are n^3 of them.
TEST(BodySurface, RecordingBodiesFromTheSceneOrTheParticles) {
  Recording r;
  const Scene scene = small_slope(3);
  r.model = make_model(scene);
  r.model.bodies.clear();
  r.scene_json = scene_to_json(scene);
  auto surfaces = viewer::recording_surfaces(r);
  ASSERT_EQ(surfaces.size(), 1u);
  EXPECT_EQ(surfaces[0].name, "jelly");
  EXPECT_EQ(surfaces[0].triangles, make_model(scene).bodies[0].surface.triangles);

  r.scene_json.clear();
  surfaces = viewer::recording_surfaces(r);
  ASSERT_EQ(surfaces.size(), 1u);
  EXPECT_EQ(surfaces[0].num_particles, 27);
  EXPECT_EQ(surfaces[0].triangles.size(), 48u);

  r.model.mass = VecX::Ones(5);
  r.model.rest_position = VecX::Zero(15);
  surfaces = viewer::recording_surfaces(r);
  ASSERT_EQ(surfaces.size(), 1u);
  EXPECT_EQ(surfaces[0].num_particles, 5);
  EXPECT_TRUE(surfaces[0].triangles.empty());
}

TEST(Camera, ProjectsTheTargetToTheCentreAndRaysBack) {
  viewer::Camera c;
  c.target = Eigen::Vector3f(1, 2, 3);
  c.distance = 10;
  const auto centre = c.project(c.target, 640, 480);
  ASSERT_TRUE(centre);
  EXPECT_NEAR(centre->x(), 320, 1e-3);
  EXPECT_NEAR(centre->y(), 240, 1e-3);
  // A point seen at pixel (100, 50) lies on the ray through it.
  Eigen::Vector3f o, d;
  c.ray(100, 50, 640, 480, o, d);
  const auto p = c.project(o + 7.0f * d, 640, 480);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->x(), 100, 1e-2);
  EXPECT_NEAR(p->y(), 50, 1e-2);
  // Shifted (the window's panel), the centre moves right and rays follow.
  c.shift_x = 0.25f;
  EXPECT_NEAR(c.project(c.target, 640, 480)->x(), 320 + 0.25 * 320, 1e-3);
  c.ray(500, 70, 640, 480, o, d);
  EXPECT_NEAR(c.project(o + 5.0f * d, 640, 480)->x(), 500, 1e-2);
  c.shift_x = 0;
  // Up in the world is up in the picture; behind the camera is nothing.
  EXPECT_LT(c.project(c.target + Eigen::Vector3f(0, 1, 0), 640, 480)->y(), 240);
  EXPECT_FALSE(c.project(c.eye() - c.forward(), 640, 480));
}

TEST(Camera, ParsesAndFrames) {
  viewer::Camera c;
  c.parse("30,15,12");
  EXPECT_EQ(c.yaw_degrees, 30);
  EXPECT_EQ(c.pitch_degrees, 15);
  EXPECT_EQ(c.distance, 12);
  c.parse("-10,5,8,1,2,3");
  EXPECT_EQ(c.target, Eigen::Vector3f(1, 2, 3));
  for (const char* bad : {"", "1,2", "1,2,0", "1,95,3", "a,b,c", "1,2,3,4"})
    EXPECT_THROW(c.parse(bad), InputError) << bad;
  // A framed box projects inside the picture.
  const Eigen::Vector3f lo(-3, 0, -1), hi(5, 4, 2);
  const viewer::Camera framed = viewer::frame_box(lo, hi, 16.0f / 9.0f);
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3f p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                            (corner & 4) ? hi.z() : lo.z());
    const auto q = framed.project(p, 1280, 720);
    ASSERT_TRUE(q);
    EXPECT_GT(q->x(), 0);
    EXPECT_LT(q->x(), 1280);
    EXPECT_GT(q->y(), 0);
    EXPECT_LT(q->y(), 720);
  }
}

// A negative point count is refused by name before any buffer or file is made.
TEST(Export, Pc2WriterRefusesANegativePointCount) {
  TempDir dir;
  const std::string path = dir.file("bad.pc2");
  try {
    Pc2Writer writer(path, -1, 0, 1);
    FAIL() << "a PC2 writer of -1 points was made";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("num_points"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

// The OBJ sequence and the PC2 cache read back equal the recorded surface positions (to their
// precision: 9 digits, float32), and the rest OBJ gives the cache's vertex order.
TEST(Export, ObjSequenceAndPc2ReadBackTheRecordedSurface) {
  TempDir dir;
  const std::string h5 = dir.file("run.h5");
  record(h5, 0.2);
  const Recording rec = read_recording(h5);
  ASSERT_EQ(rec.frames(), 13);
  const auto surfaces = viewer::recording_surfaces(rec);
  ASSERT_EQ(surfaces.size(), 1u);
  const viewer::BodySurface& s = surfaces[0];

  ASSERT_EQ(viewer::export_obj_sequence(rec, dir.file("objs")), rec.frames());
  for (int k = 0; k < rec.frames(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "objs/frame_%04d.obj", k);
    const std::vector<ObjObject> objects = read_obj(dir.file(name));
    ASSERT_EQ(objects.size(), 1u);
    EXPECT_EQ(objects[0].name, "jelly");
    ASSERT_EQ(objects[0].vertices.size(), static_cast<size_t>(s.num_vertices()));
    EXPECT_EQ(objects[0].triangles, s.triangles);
    for (int v = 0; v < s.num_vertices(); ++v)
      EXPECT_LT((objects[0].vertices[v] - s.vertex(rec.position[k], v)).norm(), 1e-7)
          << "frame " << k << " vertex " << v;
  }

  const std::string rest = viewer::export_pc2(rec, dir.file("run.pc2"));
  EXPECT_EQ(rest, dir.file("run.obj"));
  const Pc2Data pc2 = read_pc2(dir.file("run.pc2"));
  EXPECT_EQ(pc2.num_points, s.num_vertices());
  EXPECT_EQ(pc2.start_frame, 0);
  EXPECT_EQ(pc2.sample_rate, 1);
  ASSERT_EQ(pc2.samples.size(), static_cast<size_t>(rec.frames()));
  for (int k = 0; k < rec.frames(); ++k)
    for (int v = 0; v < s.num_vertices(); ++v) {
      const Vec3 expected = s.vertex(rec.position[k], v);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(pc2.samples[k][3 * v + c], static_cast<float>(expected[c]));
    }
  const std::vector<ObjObject> rest_objects = read_obj(rest);
  ASSERT_EQ(rest_objects.size(), 1u);
  for (int v = 0; v < s.num_vertices(); ++v)
    EXPECT_LT((rest_objects[0].vertices[v] - s.vertex(rec.model.rest_position, v)).norm(), 1e-7);
}

// Every body's surface, in the model's order: one object each in the sequence, one group each
// of the rest OBJ, all their vertices in the cache.
TEST(Export, EveryBody) {
  TempDir dir;
  const Scene scene = load_scene(JELLY_VIEWER_TEST_DIR "/three_bodies.json");
  Simulator sim = make_simulator(scene);
  RecorderOptions options;
  options.scene_json = scene_to_json(scene);
  options.write_xdmf = false;
  {
    H5Recorder recorder(dir.file("r.h5"), sim, options);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(0.1).ok());
  }
  const Recording rec = read_recording(dir.file("r.h5"));
  const auto surfaces = viewer::recording_surfaces(rec);
  ASSERT_EQ(surfaces.size(), 3u);
  viewer::export_obj_sequence(rec, dir.file("objs"));
  const std::string rest = viewer::export_pc2(rec, dir.file("r.pc2"));
  const std::vector<ObjObject> frame = read_obj(dir.file("objs/frame_0006.obj"));
  const std::vector<ObjObject> rest_parts = read_obj(rest);
  ASSERT_EQ(frame.size(), 3u);
  ASSERT_EQ(rest_parts.size(), 3u);
  int points = 0;
  for (size_t b = 0; b < 3; ++b) {
    EXPECT_EQ(frame[b].name, scene.bodies[b].name);
    EXPECT_EQ(rest_parts[b].name, scene.bodies[b].name);
    ASSERT_EQ(frame[b].vertices.size(), static_cast<size_t>(surfaces[b].num_vertices()));
    EXPECT_FALSE(frame[b].triangles.empty());
    for (int v = 0; v < surfaces[b].num_vertices(); ++v)
      EXPECT_LT((frame[b].vertices[v] - surfaces[b].vertex(rec.position[6], v)).norm(), 1e-6);
    points += surfaces[b].num_vertices();
  }
  const Pc2Data pc2 = read_pc2(dir.file("r.pc2"));
  EXPECT_EQ(pc2.num_points, points);
  EXPECT_EQ(pc2.samples.size(), static_cast<size_t>(rec.frames()));
}

TEST(Export, CliWritesBothAndRejectsNothingToDo) {
  TempDir dir;
  const std::string h5 = dir.file("run.h5");
  record(h5, 0.05);
  const std::string jelly = std::string("'") + JELLY_CLI + "' ";
  testing::Result r = testing::run(jelly + "export '" + h5 + "' --obj-sequence '" +
                                       dir.file("seq") + "' --pc2 '" + dir.file("c.pc2") + "'",
                                   dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("seq/frame_0003.obj")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("c.obj")));
  EXPECT_EQ(read_pc2(dir.file("c.pc2")).samples.size(), 4u);
  const std::string again = jelly + "export '" + h5 + "' --pc2 '" + dir.file("c.pc2") + "'";
  r = testing::run(again, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(testing::run(again + " --overwrite", dir).code, 0);
  r = testing::run(jelly + "export '" + h5 + "' --obj-sequence '" + dir.file("seq") + "'", dir);
  EXPECT_EQ(r.code, 2);
  r = testing::run(jelly + "export '" + h5 + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--obj-sequence"), std::string::npos) << r.err;
}

// Without a display `jelly view` says so and exits 2 (no crash, no hang).
TEST(ViewCli, ExitsTwoWithoutADisplay) {
  TempDir dir;
  const testing::Result r =
      testing::run(std::string("env -u DISPLAY -u WAYLAND_DISPLAY '") + JELLY_CLI + "' view '" +
                       JELLY_SCENES_DIR + "/seed_slope.json' --frames 1",
                   dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("display"), std::string::npos) << r.err;
}

// Lockstep frames are the Simulator's own trajectory, bit for bit.
TEST(LiveSimulation, LockstepFollowsTheSimulator) {
  const Scene scene = small_slope();
  viewer::LiveSimulation live(scene, false);
  Simulator reference = make_simulator(scene);
  for (const Real t : {0.1, 0.25, 0.5}) {
    live.advance_to(t);
    ASSERT_TRUE(live.refresh());
    ASSERT_TRUE(reference.run_until(t).ok());
    EXPECT_EQ(live.front().t, reference.state().t);
    EXPECT_EQ(live.front().steps, reference.total_steps());
    EXPECT_TRUE(live.front().x == reference.state().x);
    EXPECT_NEAR(live.front().center_of_mass.y(),
                center_of_mass(reference.model(), reference.state()).y(), 1e-12);
  }
}

// The drag pulls its particle towards the target, with an explicit integrator at its step and
// with implicit Euler at 1/60.
TEST(LiveSimulation, DragPullsTheParticle) {
  for (const auto& [integrator, dt] :
       {std::pair{"rk4", "0.001"}, {"implicit_euler", "0.0166667"}}) {
    SCOPED_TRACE(integrator);
    const Scene scene =
        small_slope(4, {"gravity=[0,0,0]", std::string("integrator.name=") + integrator,
                        std::string("integrator.dt=") + dt});
    viewer::LiveSimulation live(scene, false);
    live.refresh();
    const int p = cube_index(4, 3, 3, 3);
    const Vec3 start = particle(live.front().x, p);
    const Vec3 target = start + Vec3(1, 0.5, 0);
    live.set_drag(AnchorSpring{p, target, 20.0 * 64, std::sqrt(20.0 * 64)});
    live.advance_to(1.0);
    ASSERT_TRUE(live.refresh());
    ASSERT_EQ(live.front().status, RunStatus::kCompleted) << live.front().message;
    const Vec3 end = particle(live.front().x, p);
    EXPECT_LT((end - target).norm(), 0.5 * (start - target).norm());
    // Released, it no longer pulls: with no gravity the momentum stays.
    live.set_drag(std::nullopt);
    live.advance_to(1.5);
    live.refresh();
    EXPECT_TRUE(live.front().x.allFinite());
  }
}

// Play, pause, step, reset and a live change of integrator and dt, on the simulation thread.
TEST(LiveSimulation, ThreadTakesCommands) {
  viewer::LiveSimulation live(small_slope(), true);
  const auto wait_for = [&](auto done) {
    for (int i = 0; i < 2000; ++i) {
      live.refresh();
      if (done(live.front())) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  };
  live.set_speed(0);  // as fast as possible
  live.set_playing(true);
  ASSERT_TRUE(wait_for([](const viewer::LiveFrame& f) { return f.t > 0.05; }));
  live.set_playing(false);
  ASSERT_TRUE(wait_for([](const viewer::LiveFrame& f) { return !f.playing; }));
  const Real paused_at = live.front().t;
  const long paused_steps = live.front().steps;
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  live.refresh();
  EXPECT_EQ(live.front().t, paused_at);
  live.step_once();
  ASSERT_TRUE(wait_for([&](const viewer::LiveFrame& f) { return f.steps == paused_steps + 1; }));
  EXPECT_NEAR(live.front().t - paused_at, 0.001, 1e-12);

  viewer::LiveSettings settings = live.settings();
  settings.integrator = "implicit_euler";
  settings.dt = 1.0 / 60;
  live.apply(settings);
  live.step_once();
  ASSERT_TRUE(wait_for([&](const viewer::LiveFrame& f) { return f.steps == paused_steps + 2; }));
  EXPECT_NEAR(live.front().t - paused_at, 0.001 + 1.0 / 60, 1e-9);

  settings.integrator = "rk5";
  EXPECT_THROW(live.apply(settings), InputError);

  live.reset();
  ASSERT_TRUE(wait_for([](const viewer::LiveFrame& f) { return f.t == 0 && f.steps == 0; }));
}

// The live run pauses at the scene's duration (issue 40, item 3: it ran on for ever); Play goes
// on past it.
TEST(LiveSimulation, PausesAtTheScenesDuration) {
  viewer::LiveSimulation live(small_slope(4, {"duration=0.1"}), true);
  const auto wait_for = [&](auto done) {
    for (int i = 0; i < 2000; ++i) {
      live.refresh();
      if (done(live.front())) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  };
  live.set_speed(0);
  live.set_playing(true);
  ASSERT_TRUE(wait_for([](const viewer::LiveFrame& f) { return f.t > 0 && !f.playing; }));
  EXPECT_EQ(live.front().steps, 100);
  EXPECT_NEAR(live.front().t, 0.1, 1e-9);
  EXPECT_FALSE(live.playing());
  live.set_playing(true);
  ASSERT_TRUE(wait_for([](const viewer::LiveFrame& f) { return f.t > 0.15; }));
  live.set_playing(false);
}

// A stiff cube and a soft one on a floor: each body keeps its own springs whatever the panel
// changes (issue 40, item 1: every body took the first body's).
constexpr const char* kStiffAndSoft = R"({
  "bodies": [
    {"kind": "cube", "name": "stiff", "n": 3, "edge_length": 1, "origin": [-2, 0.5, 0],
     "springs": {"structural": {"ks": 5000, "kd": 5}, "shear": {"ks": 5000, "kd": 5},
                 "bending": {"ks": 5000, "kd": 5}}},
    {"kind": "cube", "name": "soft", "n": 3, "edge_length": 1, "origin": [2, 0.5, 0],
     "springs": {"structural": {"ks": 3, "kd": 0.5}, "shear": {"ks": 3, "kd": 0.5},
                 "bending": {"ks": 3, "kd": 0.5}}}
  ],
  "terrains": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                "contact": {"model": "coulomb"}}],
  "integrator": {"name": "rk4", "dt": 0.001},
  "duration": 1
})";

// A panel change (integrator, dt, gravity, contact) goes on from the current state with every
// body's own springs: bit for bit what the simulator does with the same live edits.
TEST(LiveSimulation, PanelChangesKeepEveryBodysSprings) {
  const Scene scene = parse_scene(kStiffAndSoft);
  viewer::LiveSimulation live(scene, false);
  Simulator reference = make_simulator(scene);
  live.advance_to(0.05);
  ASSERT_TRUE(reference.run_until(0.05).ok());

  viewer::LiveSettings settings = live.settings();
  ASSERT_EQ(settings.springs.size(), 2u);
  EXPECT_EQ(settings.springs[1][0].ks, 3);
  settings.integrator = "midpoint";
  settings.dt = 0.0005;
  settings.gravity = Vec3(0, -9.0, 0);
  settings.contacts[0].friction = 0.3;
  settings.contacts[0].static_friction = std::max(0.3, settings.contacts[0].static_friction);
  live.apply(settings);
  live.advance_to(0.3);
  ASSERT_TRUE(live.refresh());

  reference.set_integrator(make_integrator("midpoint", {}));
  reference.set_dt(0.0005);
  reference.set_gravity(Vec3(0, -9.0, 0));
  reference.terrains()[0]->set_contact(settings.contacts[0]);
  ASSERT_TRUE(reference.run_until(0.3).ok());
  EXPECT_TRUE(live.front().x == reference.state().x);

  // Each body's springs are still its own, in the simulator and in the panel's settings.
  const Model& model = live.simulator().model();
  for (int b = 0; b < 2; ++b) {
    const Body& body = model.bodies[static_cast<size_t>(b)];
    for (int s = body.first_spring; s < body.end_spring(); ++s)
      EXPECT_EQ(model.springs.ks[static_cast<size_t>(s)], b == 0 ? 5000 : 3) << "spring " << s;
  }
  EXPECT_EQ(live.settings().springs[0][0].ks, 5000);
  EXPECT_EQ(live.settings().springs[1][0].ks, 3);

  // A change of one body's springs leaves the other's alone.
  settings.springs[1][0].ks = 7;
  live.apply(settings);
  live.advance_to(0.31);
  const Body& soft = model.bodies[1];
  const Body& stiff = model.bodies[0];
  for (int s = soft.first_spring; s < soft.end_spring(); ++s) {
    if (model.springs.type[static_cast<size_t>(s)] == SpringType::kStructural) {
      EXPECT_EQ(model.springs.ks[static_cast<size_t>(s)], 7);
    }
  }
  for (int s = stiff.first_spring; s < stiff.end_spring(); ++s)
    EXPECT_EQ(model.springs.ks[static_cast<size_t>(s)], 5000);
}

// A diverging run stops with the divergence guard's reason instead of crashing.
TEST(LiveSimulation, DivergenceStopsWithTheReason) {
  viewer::LiveSimulation live(
      small_slope(4, {"integrator.name=explicit_euler", "integrator.dt=0.05"}), false);
  live.advance_to(20);
  ASSERT_TRUE(live.refresh());
  EXPECT_EQ(live.front().status, RunStatus::kDiverged);
  EXPECT_NE(live.front().message.find("diverged at t ="), std::string::npos)
      << live.front().message;
  EXPECT_LT(live.front().t, 20);
  // The time in 4 significant digits, not the accumulated 0.35000000000000003.
  const std::string& message = live.front().message;
  const size_t at = message.find("t = ") + 4;
  EXPECT_LE(message.find(" s", at) - at, 6u) << message;
  live.reset();
  live.advance_to(0.1);
  live.refresh();
  EXPECT_EQ(live.front().status, RunStatus::kCompleted);
}

TEST(RecordingView, VideoFramesFollowTheClock) {
  TempDir dir;
  record(dir.file("run.h5"), 0.5);
  const viewer::RecordingView view(dir.file("run.h5"));
  EXPECT_EQ(view.frames(), 31);
  EXPECT_NEAR(view.native_fps(), 60, 1e-9);
  const std::vector<int> all = view.video_frames(60, 0, 0.5);
  ASSERT_EQ(all.size(), 31u);
  for (int k = 0; k < 31; ++k) EXPECT_EQ(all[k], k);
  const std::vector<int> half = view.video_frames(30, 0, 0.5);
  ASSERT_EQ(half.size(), 16u);
  EXPECT_EQ(half[5], 10);
  EXPECT_EQ(view.frame_at(0.26), 16);
  EXPECT_EQ(view.frame_at(-1), 0);
  EXPECT_EQ(view.frame_at(9), 30);
}

}  // namespace
}  // namespace jelly
