// Scene files: the seed scenes load to the seed facts, scenes round-trip through JSON, and every
// kind of bad scene or --set override is an InputError with a precise message.
#include <jelly/core/detail/json.hpp>
#include <jelly/io/scene.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

#include "scene_files.hpp"
#include "support/temp_dir.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

using testing::scene_path;

// Every scene file the project ships.
std::vector<std::string> shipped_scenes() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(JELLY_SCENES_DIR)) {
    if (entry.path().extension() == ".json") names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The InputError message of parsing `text` with `overrides`, or "" when it parses.
std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A valid scene with one terrain of each kind, to be broken by overrides in the tests.
const char* const kGood = R"({
  "terrains": [
    {"kind": "slope", "contact": {"model": "seed"}},
    {"kind": "elevator", "motion": [{"duration": 1, "acceleration": 2},
                                    {"duration": 1, "acceleration": -2}]},
    {"kind": "plane", "normal": [0, 1, 0]}
  ],
  "integrator": {"name": "rk4"},
  "duration": 1
})";

// Scenes are equal when they write the same JSON: scene_to_json writes every field.
void expect_same_scene(const Scene& a, const Scene& b) {
  EXPECT_EQ(scene_to_json(a), scene_to_json(b));
}

TEST(SeedScenes, SlopeIsTheSeedSlope) {
  const Scene scene = load_scene(scene_path("seed_slope.json"));
  ASSERT_EQ(scene.bodies.size(), 1u);
  EXPECT_EQ(scene.bodies[0].name, "jelly");
  const CubeSpec cube = scene.cube();
  EXPECT_EQ(cube.n, 10);
  EXPECT_EQ(cube.edge_length, 4);
  EXPECT_EQ(cube.origin, Vec3(-20.0 / 9, 61.0 / 9, -20.0 / 9));
  EXPECT_EQ(cube.particle_mass, 1);
  for (int t = 0; t < kSpringTypeCount; ++t) {
    EXPECT_EQ(cube.springs[t].ks, 1400);
    EXPECT_EQ(cube.springs[t].kd, 50);
  }
  EXPECT_EQ(scene.gravity, Vec3(0, -9.8, 0));
  EXPECT_EQ(scene.integrator.name, "rk4");
  EXPECT_EQ(scene.integrator.dt, 0.001);
  EXPECT_EQ(scene.output_interval, 1.0 / 60);

  const Model model = make_model(scene);
  EXPECT_EQ(model.springs.size(), 12876);
  const Vec3 com = center_of_mass(model, model.rest_position);
  EXPECT_NEAR(com.x(), -0.2222, 1e-4);
  EXPECT_NEAR(com.y(), 8.7778, 1e-4);
  EXPECT_NEAR(com.z(), -0.2222, 1e-4);

  ASSERT_EQ(scene.terrains.size(), 1u);
  const TerrainSpec& slope = *scene.terrains[0];
  EXPECT_EQ(slope.kind(), "slope");
  EXPECT_EQ(slope.contact.model, ContactModel::kSeed);
  EXPECT_EQ(slope.contact.restitution, 0.8);
  EXPECT_EQ(slope.contact.friction, 0.5);
  EXPECT_EQ(slope.contact.epsilon, 0.01);
  const auto terrain = make_terrain(slope);
  const auto* plane = dynamic_cast<const Plane*>(terrain.get());
  ASSERT_NE(plane, nullptr);
  const Real a = 20 * M_PI / 180;
  EXPECT_NEAR((plane->unit_normal() - Vec3(std::sin(a), std::cos(a), 0)).norm(), 0, 1e-15);
  EXPECT_EQ(plane->point(), Vec3::Zero());
}

TEST(SeedScenes, ElevatorIsTheSeedElevator) {
  const Scene scene = load_scene(scene_path("seed_elevator.json"));
  EXPECT_EQ(make_model(scene).springs.size(), 12876);
  ASSERT_EQ(scene.terrains.size(), 1u);
  const ElevatorSpec& t = scene.terrains[0].as<ElevatorSpec>();
  EXPECT_EQ(t.kind(), "elevator");
  EXPECT_EQ(t.center, Vec3(0, 1, 0));
  EXPECT_EQ(t.size_x, 5);
  EXPECT_EQ(t.size_z, 5);
  EXPECT_EQ(t.mass, 1);
  EXPECT_EQ(t.contact.model, ContactModel::kSeed);
  EXPECT_EQ(t.contact.restitution, 0.8);
  const ElevatorMotion seed = ElevatorMotion::seed();
  ASSERT_EQ(t.motion.phases().size(), seed.phases().size());
  for (Real time : {0.5, 1.9, 2.5, 3.7, 4.2, 9.9}) {
    EXPECT_EQ(t.motion.offset(time), seed.offset(time)) << time;
  }
  const Simulator sim = make_simulator(scene);
  ASSERT_EQ(sim.terrains().size(), 1u);
  EXPECT_EQ(sim.terrains()[0]->kind(), "elevator");
  EXPECT_EQ(sim.terrains()[0]->mass(), 1);
}

TEST(Scenes, EveryShippedSceneRoundTrips) {
  for (const std::string& name : shipped_scenes()) {
    SCOPED_TRACE(name);
    const Scene first = load_scene(scene_path(name));
    const std::string text = scene_to_json(first);
    const Scene second = parse_scene(text);
    expect_same_scene(first, second);
    EXPECT_EQ(scene_to_json(second), text);
  }
}

TEST(Scenes, RoundTripKeepsEveryNonDefaultField) {
  Scene s = parse_scene(kGood);
  s.description = "all fields";
  CubeSpec cube = s.cube();
  cube.n = 3;
  cube.edge_length = 1.5;
  cube.origin = Vec3(0.1, 0.2, 0.3);
  cube.particle_mass = 0.25;
  cube.springs[2] = {700, 3};
  cube.gravity = Vec3(0, 0, -1);
  s.set_cube(cube);
  s.bodies[0].radius = 0.3;
  s.terrains[0].as<SlopeSpec>().angle_degrees = -15;
  s.terrains[0].as<SlopeSpec>().point = Vec3(1, 0, 0);
  s.terrains[1].as<ElevatorSpec>().mass = std::numeric_limits<Real>::infinity();
  s.terrains[1].as<ElevatorSpec>().thickness = 0.5;
  s.terrains[2].as<PlaneSpec>().point = Vec3(0, -1, 0);
  s.terrains[2].as<PlaneSpec>().normal = Vec3(0.1, 1, 0);
  s.terrains[2]->contact.static_friction = 0.9;
  s.terrains[2]->contact.resting_speed = 0.02;
  s.integrator = {"midpoint", 0.002, {}};
  s.duration = 2.5;
  s.output_interval = 0;
  s.divergence = {100, 50};
  s.max_particles = 5000;
  s.body_contact.self_contact = true;
  s.body_contact.friction = 0.2;
  s.body_contact.iterations = 7;
  s.threads = 3;
  const Scene back = parse_scene(scene_to_json(s));
  expect_same_scene(s, back);
  EXPECT_EQ(back.cube().n, 3);
  EXPECT_EQ(back.gravity, Vec3(0, 0, -1));
  EXPECT_EQ(back.terrains[2].as<PlaneSpec>().normal, Vec3(0.1, 1, 0));
  EXPECT_EQ(back.threads, 3);
}

TEST(Scenes, MissingFieldsTakeTheSeedDefaults) {
  const Scene s = parse_scene(
      R"({"terrains": [{"kind": "plane"}], "integrator": {"name": "rk4"}, "duration": 2})");
  expect_same_scene(s, [] {
    Scene d;
    d.integrator.name = "rk4";
    d.duration = 2;
    d.terrains.emplace_back(PlaneSpec());
    return d;
  }());
  EXPECT_EQ(s.terrains[0]->contact.model, ContactModel::kCoulomb);
  EXPECT_EQ(s.terrains[0].as<PlaneSpec>().normal, Vec3::UnitY());
  EXPECT_EQ(s.integrator.dt, 0.001);
}

TEST(Scenes, CommentsAreAllowed) {
  EXPECT_EQ(error_of("// a scene\n{\"integrator\": {\"name\": \"rk4\"}, /* s */ \"duration\": 1}"),
            "");
}

TEST(BadScenes, UnknownKeysNameTheirPathAndTheAllowedKeys) {
  EXPECT_EQ(error_of(kGood, {"terrains[0].contact.restitutoin=0.5"}),
            "terrains[0].contact.restitutoin = 0.5 is invalid: unknown key; allowed here: "
            "\"model\", \"restitution\", \"friction\", \"static_friction\", \"epsilon\", "
            "\"resting_speed\"");
  EXPECT_EQ(error_of(kGood, {"terrains.0.normal=[0,1,0]"}),
            "terrains[0].normal = [0,1,0] is invalid: unknown key; allowed here: \"kind\", "
            "\"angle_degrees\", \"point\", \"contact\"");
  EXPECT_EQ(error_of(kGood, {"springs.stuctural.ks=1"}),
            "springs.stuctural = {\"ks\":1} is invalid: unknown key; allowed here: "
            "\"structural\", \"shear\", \"bending\"");
  EXPECT_THAT(error_of(kGood, {"durration=3"}),
              StartsWith("durration = 3 is invalid: unknown key; allowed here: \"description\", "
                         "\"bodies\", \"cube\", \"springs\", \"gravity\", \"max_particles\", "
                         "\"terrains\", \"body_contact\", \"integrator\", \"duration\", "
                         "\"output_interval\", \"divergence\""));
  EXPECT_EQ(error_of(kGood, {"integrator.options.newton=2"}),
            "integrator.options.newton = 2 is invalid: unknown key; allowed here: none");
}

TEST(BadScenes, WrongTypes) {
  EXPECT_EQ(error_of(kGood, {"cube.n=ten"}), "cube.n = \"ten\" is invalid: an integer");
  EXPECT_EQ(error_of(kGood, {"cube.n=2.5"}), "cube.n = 2.5 is invalid: an integer");
  EXPECT_EQ(error_of(kGood, {"cube.origin=[1,2]"}),
            "cube.origin = [1,2] is invalid: an array of 3 numbers [x, y, z]");
  EXPECT_EQ(error_of(kGood, {"terrains[1].motion[0].stop_at_end=1"}),
            "terrains[1].motion[0].stop_at_end = 1 is invalid: true or false");
  EXPECT_EQ(error_of(kGood, {"terrains[1].mass=heavy"}),
            "terrains[1].mass = \"heavy\" is invalid: a number or \"inf\"");
  EXPECT_EQ(error_of(kGood, {"terrains[1].motion=up"}),
            "terrains[1].motion = \"up\" is invalid: \"seed\" or a list of phases "
            "[{\"duration\": 2, \"acceleration\": 3, \"stop_at_end\": true}, ...]");
  EXPECT_EQ(error_of(kGood, {"integrator=rk4"}),
            "integrator = \"rk4\" is invalid: a JSON object {...}");
  EXPECT_EQ(error_of(kGood, {"terrains={}"}),
            "terrains = {} is invalid: a list of terrains [{...}, ...]");
  EXPECT_EQ(error_of("[1, 2]"), "scene = [1,2] is invalid: a JSON object {...}");
}

TEST(BadScenes, OutOfRangeValuesSayWhatIsAllowed) {
  EXPECT_EQ(error_of(kGood, {"terrains[0].contact.restitution=1.5"}),
            "terrains[0].contact.restitution = 1.5 is invalid: a number in [0, 1]");
  EXPECT_EQ(error_of(kGood, {"terrains[2].contact.static_friction=0.1"}),
            "terrains[2].contact.static_friction = 0.10000000000000001 is invalid: a finite "
            "number >= friction (0.5)");
  EXPECT_EQ(error_of(kGood, {"terrains[0].contact.model=ice"}),
            "terrains[0].contact.model = \"ice\" is invalid: one of \"coulomb\", \"seed\", "
            "\"seed_framework\"");
  EXPECT_EQ(error_of(kGood, {"cube.n=1"}), "cube.n = 1 is invalid: an integer in [2, 400]");
  EXPECT_EQ(error_of(kGood, {"springs.shear.kd=-1"}),
            "springs.shear.kd = -1 is invalid: a finite damping >= 0");
  EXPECT_EQ(error_of(kGood, {"terrains[1].size_x=0"}),
            "terrains[1].size_x = 0 is invalid: a finite size > 0");
  EXPECT_EQ(error_of(kGood, {"terrains[1].motion[1].duration=0"}),
            "terrains[1].motion[1].duration = 0 is invalid: a finite duration > 0 s");
  EXPECT_THAT(
      error_of(kGood, {"terrains[1].motion[1].stop_at_end=false"}),
      StartsWith(
          "terrains[1].motion = a cycle ending at -2 m/s is invalid: a cycle that ends at rest"));
  EXPECT_EQ(error_of(kGood, {"terrains[0].angle_degrees=90"}),
            "terrains[0].angle_degrees = 90 is invalid: an angle in (-90, 90) degrees");
  EXPECT_EQ(error_of(kGood, {"terrains[2].normal=[0,0,0]"}),
            "terrains[2].normal = 0 0 0 is invalid: a finite, non-zero vector");
  EXPECT_EQ(error_of(kGood, {"terrains[2].kind=wall"}),
            "terrains[2].kind = \"wall\" is invalid: one of \"box\", \"capsule\", \"cylinder\", "
            "\"elevator\", \"mesh\", \"plane\", \"slope\", \"sphere\"");
  EXPECT_EQ(error_of(kGood, {"integrator.dt=0"}),
            "integrator.dt = 0 is invalid: a finite time step > 0 s");
  EXPECT_EQ(error_of(kGood, {"duration=-1"}), "duration = -1 is invalid: a finite duration > 0 s");
  EXPECT_EQ(error_of(kGood, {"output_interval=-1"}),
            "output_interval = -1 is invalid: a finite interval >= 0 s (0 = every step)");
  EXPECT_EQ(error_of(kGood, {"divergence.max_speed=0"}),
            "divergence.max_speed = 0 is invalid: a speed > 0 m/s");
  EXPECT_EQ(error_of(kGood, {"threads=-1"}),
            "threads = -1 is invalid: an integer >= 0 (0 = all cores)");
  EXPECT_EQ(error_of(kGood, {"threads=1.5"}), "threads = 1.5 is invalid: an integer");
  const std::string unknown = error_of(kGood, {"integrator.name=rk5"});
  EXPECT_THAT(unknown, StartsWith("integrator.name = \"rk5\" is invalid: one of "));
  for (const std::string& name : integrator_names()) {
    EXPECT_THAT(unknown, HasSubstr("\"" + name + "\""));
  }
}

TEST(BadScenes, MissingRequiredFields) {
  EXPECT_EQ(error_of(R"({"duration": 1})"),
            "integrator is missing: it is required ({\"name\": ...})");
  EXPECT_EQ(error_of(R"({"integrator": {"dt": 0.01}, "duration": 1})"),
            "integrator.name is missing: it is required");
  EXPECT_EQ(error_of(R"({"integrator": {"name": "rk4"}})"), "duration is missing: it is required");
  EXPECT_EQ(error_of(R"({"terrains": [{}], "integrator": {"name": "rk4"}, "duration": 1})"),
            "terrains[0].kind is missing: it is required");
  EXPECT_EQ(error_of(kGood, {"terrains[1].motion=[{\"duration\": 1}]"}),
            "terrains[1].motion[0].acceleration is missing: it is required");
}

TEST(BadScenes, FilesThatCannotBeReadOrAreNotJson) {
  EXPECT_THROW(load_scene(scene_path("no_such_scene.json")), InputError);
  try {
    load_scene(scene_path("no_such_scene.json"));
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), StartsWith("cannot read the scene file '"));
  }
  EXPECT_THAT(error_of("{\"duration\": 1,}"), StartsWith("scene is not valid JSON: parse error"));
}

TEST(Overrides, SetValuesAlongDottedAndIndexedPaths) {
  const Scene s = parse_scene(
      kGood, {"springs.structural.ks=2400", "terrains[0].contact.restitution=0.25",
              "terrains.2.contact.model=seed", "integrator.name=midpoint", "cube.origin=[0, 1, 2]",
              "description=a \"quoted\" = text", "terrains[1].mass=inf"});
  EXPECT_EQ(s.cube().springs[0].ks, 2400);
  EXPECT_EQ(s.cube().springs[1].ks, 1400);
  EXPECT_EQ(s.terrains[0]->contact.restitution, 0.25);
  EXPECT_EQ(s.terrains[2]->contact.model, ContactModel::kSeed);
  EXPECT_EQ(s.integrator.name, "midpoint");
  EXPECT_EQ(s.cube().origin, Vec3(0, 1, 2));
  EXPECT_EQ(s.description, "a \"quoted\" = text");
  EXPECT_TRUE(std::isinf(s.terrains[1].as<ElevatorSpec>().mass));
}

TEST(Overrides, TheTextVersionReturnsTheEditedScene) {
  const std::string text = apply_override(kGood, "terrains[2].point=[0,-1,0]");
  EXPECT_EQ(parse_scene(text).terrains[2].as<PlaneSpec>().point, Vec3(0, -1, 0));
}

TEST(Overrides, BadPathsAreInputErrors) {
  EXPECT_EQ(error_of(kGood, {"terrains.3.contact.restitution=0.5"}),
            "--set 'terrains.3.contact.restitution=0.5': terrains[3] does not exist (terrains "
            "has 3 elements)");
  EXPECT_EQ(error_of(kGood, {"duration.value=1"}),
            "--set 'duration.value=1': duration is 1, not an object with a key \"value\"");
  EXPECT_EQ(error_of(kGood, {"integrator[0]=1"}),
            "--set 'integrator[0]=1': integrator is not an array");
  EXPECT_EQ(error_of(kGood, {"springs.structural.ks"}),
            "--set 'springs.structural.ks': expected path=value, e.g. springs.structural.ks=2400");
  EXPECT_EQ(error_of(kGood, {"springs..ks=1"}),
            "--set 'springs..ks=1': empty key in the path 'springs..ks'");
  EXPECT_EQ(error_of(kGood, {"terrains[x].kind=plane"}),
            "--set 'terrains[x].kind=plane': 'terrains[x]' is not a key or key[index] (indices are "
            "integers >= 0)");
  EXPECT_EQ(error_of(kGood, {"=1"}), "--set '=1': empty key in the path ''");
}

TEST(MakeSimulator, BuildsTheSceneAndRunsIt) {
  // The library API of the README, on a small cube.
  Scene scene = load_scene(scene_path("seed_slope.json"), {"cube.n=4"});
  scene.integrator.name = "symplectic_euler";
  scene.integrator.dt = 0.002;
  Simulator sim = make_simulator(scene);
  EXPECT_EQ(sim.integrator().name(), "symplectic_euler");
  EXPECT_EQ(sim.options().dt, 0.002);
  EXPECT_EQ(sim.options().output_interval, 1.0 / 60);
  EXPECT_EQ(sim.options().threads, 0);  // all cores
  EXPECT_EQ(
      make_simulator(load_scene(scene_path("seed_slope.json"), {"threads=2"})).options().threads,
      2);
  ASSERT_EQ(sim.terrains().size(), 1u);
  EXPECT_EQ(sim.terrains()[0]->contact().model, ContactModel::kSeed);
  const RunReport report = sim.run_until(0.2);
  EXPECT_TRUE(report.ok()) << report.brief();
  const Vec3 com = center_of_mass(sim.model(), sim.state());
  // Free fall for 0.2 s (the cube is still far above the slope): y drops by g t^2 / 2.
  EXPECT_NEAR(com.y(), 79.0 / 9 - 0.5 * 9.8 * 0.2 * 0.2, 1e-2);
}

// scenes/gummy_bear.json: the voxelized bear (its surface the mesh of assets/gummy_bear.obj)
// falls freely, its centre of mass on the parabola, then lands on the slope and slides down it
// (towards +x) without any particle passing through the slope.
TEST(MakeSimulator, GummyBearFallsThenLandsOnTheSlope) {
  Simulator sim = make_simulator(load_scene(scene_path("gummy_bear.json")));
  const Model& model = sim.model();
  ASSERT_EQ(model.num_bodies(), 1);
  EXPECT_EQ(model.bodies[0].kind, "voxelized");
  EXPECT_EQ(model.bodies[0].surface.num_triangles(), 3836);  // the mesh's
  EXPECT_GT(model.num_particles(), 500);
  const Vec3 start = center_of_mass(model, sim.state());
  const Real t = 0.1;  // still in the air (its lowest point is 2 m above the slope)
  ASSERT_TRUE(sim.run_until(t).ok());
  const Vec3 fallen = center_of_mass(model, sim.state());
  EXPECT_NEAR(fallen.y(), start.y() - 0.5 * 9.8 * t * t, 1e-9);
  EXPECT_NEAR(fallen.x(), start.x(), 1e-9);
  // Every 10 ms up to 1.5 s: the particles' heights above the slope (their centres; the contact
  // radius is 3.5 cm).
  const Vec3 normal(std::sin(20 * M_PI / 180), std::cos(20 * M_PI / 180), 0);
  Real lowest = 1e9, touched = 1e9;
  for (int frame = 1; frame <= 140; ++frame) {
    ASSERT_TRUE(sim.run_until(t + 0.01 * frame).ok());
    lowest = 1e9;
    for (int i = 0; i < model.num_particles(); ++i) {
      lowest = std::min(lowest, normal.dot(particle(sim.state().x, i)));
    }
    ASSERT_GT(lowest, -0.02) << "through the slope at t = " << sim.state().t;
    touched = std::min(touched, lowest);
  }
  EXPECT_LT(touched, 0.035);                                            // it landed
  EXPECT_GT(center_of_mass(model, sim.state()).x(), start.x() + 0.05);  // sliding or rolling down
}

// scenes/jelly_stack.json: the three cubes come to rest on each other, no particle of one body
// closer to one of another than the sum of their radii less 1 %.
TEST(MakeSimulator, JellyStackComesToRestWithoutOverlap) {
  Simulator sim = make_simulator(load_scene(scene_path("jelly_stack.json")));
  const auto centres = [&sim] {
    std::vector<Vec3> c;
    for (const Body& b : sim.model().bodies) {
      Vec3 sum = Vec3::Zero();
      for (int i = b.first_particle; i < b.end_particle(); ++i) sum += particle(sim.state().x, i);
      c.push_back(sum / b.num_particles);
    }
    return c;
  };
  ASSERT_TRUE(sim.run_until(5.0).ok());
  const std::vector<Vec3> settled = centres();
  ASSERT_TRUE(sim.run_until(6.0).ok());
  const Model& m = sim.model();
  // Still: the buzz below moves a centre by about a millimetre at random, it does not creep.
  for (int b = 0; b < 3; ++b) EXPECT_LT((centres()[b] - settled[b]).norm(), 3e-3) << b;
  ASSERT_EQ(m.num_bodies(), 3);
  Real worst = 1e9, fastest = 0;
  for (int i = 0; i < m.num_particles(); ++i) {
    fastest = std::max(fastest, particle(sim.state().v, i).norm());
    for (int j = i + 1; j < m.num_particles(); ++j) {
      const Body& a = m.body_of(i);
      const Body& b = m.body_of(j);
      if (&a == &b) continue;
      const Real d = (particle(sim.state().x, j) - particle(sim.state().x, i)).norm();
      worst = std::min(worst, d / (a.radius + b.radius));
    }
  }
  EXPECT_GT(worst, 0.99);
  // Single particles in resting contact keep a buzz of 0.05-0.1 m/s, 0.2 mm amplitude at these
  // springs' 35 Hz (docs/contact.md).
  EXPECT_LT(fastest, 0.2);
  // Stacked: each cube's centre above the one below it.
  std::vector<Real> y;
  for (const Body& b : m.bodies) {
    Real sum = 0;
    for (int i = b.first_particle; i < b.end_particle(); ++i) sum += sim.state().x[3 * i + 1];
    y.push_back(sum / b.num_particles);
  }
  EXPECT_GT(y[1], y[0] + 0.9);
  EXPECT_GT(y[2], y[1] + 0.9);
}

// Bodies that start inside each other: an error naming both, not a silent explosion.
TEST(MakeSimulator, OverlappingBodiesNameBoth) {
  Scene scene = load_scene(scene_path("jelly_stack.json"), {"bodies[1].origin=[-0.5,0.8,-0.5]"});
  try {
    make_simulator(scene);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), StartsWith("bodies \"bottom\" and \"middle\" overlap at the start: "))
        << e.what();
  }
  scene.body_contact.enabled = false;  // passing through each other is then allowed
  EXPECT_NO_THROW(make_simulator(scene));
}

TEST(MakeSimulator, RejectsAnInvalidSceneBuiltInCode) {
  Scene scene;
  scene.integrator.name = "rk4";
  scene.terrains.emplace_back(PlaneSpec());
  scene.terrains[0]->contact.friction = -1;
  try {
    make_simulator(scene);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "terrains[0].contact.friction = -1 is invalid: a finite number >= 0");
  }
}

}  // namespace
}  // namespace jelly

namespace jelly {
namespace {

// integrator.options holds the options of the named integrator: they round-trip, and a bad one
// is an error naming its scene path.
TEST(SceneIntegratorOptions, ImplicitAndArkodeOptionsRoundTrip) {
  const Scene implicit = parse_scene(
      kGood, {"integrator.name=implicit_euler", "integrator.options.newton_iterations=4",
              "integrator.options.linear_solver=cholmod", "integrator.options.definiteness=project",
              "integrator.options.ordering=amd"});
  EXPECT_EQ(implicit.integrator.options.implicit.newton_iterations, 4);
  EXPECT_EQ(implicit.integrator.options.implicit.linear_solver, ImplicitLinearSolver::kCholmod);
  EXPECT_EQ(implicit.integrator.options.implicit.definiteness, DefinitenessFix::kProjectPsd);
  const Scene again = parse_scene(scene_to_json(implicit));
  EXPECT_EQ(again.integrator.options.implicit.newton_iterations, 4);
  EXPECT_EQ(again.integrator.options.implicit.ordering, CholmodOrdering::kAmd);
  EXPECT_EQ(again.integrator.options.implicit.definiteness, DefinitenessFix::kProjectPsd);

  const Scene arkode =
      parse_scene(kGood, {"integrator.name=arkode_dirk", "integrator.options.rtol=1e-4",
                          "integrator.options.linear_solver=klu"});
  EXPECT_EQ(arkode.integrator.options.arkode.rtol, 1e-4);
  EXPECT_EQ(parse_scene(scene_to_json(arkode)).integrator.options.arkode.linear_solver,
            ArkodeLinearSolver::kKlu);
  EXPECT_NO_THROW(make_simulator(arkode));
}

TEST(SceneIntegratorOptions, BadOptionsNameTheirPath) {
  EXPECT_EQ(
      error_of(kGood, {"integrator.name=implicit_euler", "integrator.options.newton_iterations=0"}),
      "integrator.options.newton_iterations = 0 is invalid: an integer in [1, 100] (1 = "
      "linearized backward Euler)");
  EXPECT_THAT(error_of(kGood, {"integrator.name=arkode_erk", "integrator.options.rtol=-1"}),
              StartsWith("integrator.options.rtol = -1 is invalid"));
  EXPECT_THAT(error_of(kGood, {"integrator.name=implicit_euler",
                               "integrator.options.definiteness=\"soft\""}),
              StartsWith("integrator.options.definiteness = \"soft\" is invalid"));
  // The linear solver is arkode_dirk's: arkode_erk solves nothing (it was accepted, unused).
  EXPECT_EQ(error_of(kGood, {"integrator.name=arkode_erk", "integrator.options.linear_solver=klu"}),
            "integrator.options.linear_solver = \"klu\" is invalid: \"auto\" (arkode_erk "
            "solves no linear system: linear_solver is arkode_dirk's option)");
  EXPECT_NO_THROW(
      parse_scene(kGood, {"integrator.name=arkode_erk", "integrator.options.linear_solver=auto"}));
  // rtol belongs to the ARKODE integrators, not to implicit_euler.
  EXPECT_THAT(error_of(kGood, {"integrator.name=implicit_euler", "integrator.options.rtol=1e-3"}),
              StartsWith("integrator.options.rtol = 0.001 is invalid: unknown key"));
}

}  // namespace
}  // namespace jelly

namespace jelly {
namespace {

// Two cubes launched head-on by bodies[i].velocity, no gravity, no terrain: they collide
// (contact between bodies) and their total momentum stays what the scene gave them.
TEST(BodyVelocity, TwoCubesLaunchedAtEachOtherConserveMomentum) {
  const std::string json = R"({
    "bodies": [
      {"kind": "cube", "name": "left", "n": 4, "edge_length": 1, "origin": [-2, 0, 0],
       "velocity": [3, 0, 0], "particle_mass": 0.5},
      {"kind": "cube", "name": "right", "n": 4, "edge_length": 1, "origin": [1, 0.25, 0],
       "velocity": [-2, 0, 0], "angular_velocity": [0, 0, 1]}
    ],
    "gravity": [0, 0, 0], "terrains": [],
    "integrator": {"name": "rk4", "dt": 0.001}, "duration": 1
  })";
  const Scene scene = parse_scene(json);
  EXPECT_EQ(scene.bodies[0].velocity, Vec3(3, 0, 0));
  EXPECT_EQ(parse_scene(scene_to_json(scene)).bodies[1].angular_velocity, Vec3(0, 0, 1));
  Simulator sim = make_simulator(scene);
  const Model& m = sim.model();
  // 64 particles of 0.5 kg at 3 m/s, 64 of 1 kg at -2 m/s (the spin adds no momentum).
  const Vec3 p0 = linear_momentum(m, sim.state());
  EXPECT_NEAR(p0.x(), 64 * 0.5 * 3 - 64 * 2, 1e-12);
  EXPECT_NEAR(p0.y(), 0, 1e-12);
  // The right cube spins about its own centre at 1 rad/s: its angular momentum about that
  // centre is I w with I = sum m (x^2 + y^2) over its particles relative to the centre.
  const Body& right = m.bodies[1];
  Vec3 c = Vec3::Zero();
  for (int i = right.first_particle; i < right.end_particle(); ++i)
    c += particle(m.rest_position, i);
  c /= right.num_particles;
  Real inertia = 0, spin = 0;
  for (int i = right.first_particle; i < right.end_particle(); ++i) {
    const Vec3 r = particle(m.rest_position, i) - c;
    inertia += m.mass[i] * (r.x() * r.x() + r.y() * r.y());
    spin += m.mass[i] * r.cross(Vec3(particle(sim.state().v, i) - Vec3(-2, 0, 0))).z();
  }
  EXPECT_NEAR(spin, inertia * 1.0, 1e-12);
  const RunReport report = sim.run_until(1.0);
  ASSERT_TRUE(report.ok()) << report.brief();
  EXPECT_GT(sim.body_contact().stats().pairs, 0);  // they did meet
  EXPECT_LT((linear_momentum(m, sim.state()) - p0).norm(), 1e-9);
}

// A body's colour: optional, read, written back, given to the model's body, written to a
// recording's body group and read back from it (issue 40, item 7).
TEST(BodyColor, ReadWrittenAndRecorded) {
  const std::string json = R"({
    "bodies": [
      {"kind": "cube", "name": "red", "n": 3, "edge_length": 1, "origin": [-2, 0.5, 0]},
      {"kind": "cube", "name": "green", "n": 3, "edge_length": 1, "origin": [2, 0.5, 0],
       "color": [0.1, 0.8, 0.2]}
    ],
    "terrains": [], "integrator": {"name": "rk4", "dt": 0.001}, "duration": 0.02
  })";
  const Scene scene = parse_scene(json);
  EXPECT_FALSE(scene.bodies[0].color);
  ASSERT_TRUE(scene.bodies[1].color);
  EXPECT_EQ(*scene.bodies[1].color, Vec3(0.1, 0.8, 0.2));
  const Scene again = parse_scene(scene_to_json(scene));
  EXPECT_FALSE(again.bodies[0].color);
  EXPECT_EQ(again.bodies[1].color, scene.bodies[1].color);

  testing::TempDir dir;
  const std::string path = dir.file("colors.h5");
  {
    Simulator sim = make_simulator(scene);
    EXPECT_FALSE(sim.model().bodies[0].color);
    EXPECT_EQ(sim.model().bodies[1].color, scene.bodies[1].color);
    RecorderOptions options;
    options.scene_json = scene_to_json(scene);
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(0.02).ok());
  }
  const Recording r = read_recording(path);
  ASSERT_EQ(r.model.bodies.size(), 2u);
  EXPECT_FALSE(r.model.bodies[0].color);
  EXPECT_EQ(r.model.bodies[1].color, scene.bodies[1].color);

  // ParaView: the coloured body's blocks (its springs and its surface) carry the colour as a
  // field of every frame; the other body's none.
  std::string xdmf;
  {
    std::ifstream in(dir.file("colors.xdmf"));
    xdmf.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string field = "<Attribute Name=\"color\"";
  const std::string values = ">0.10000000000000001 0.80000000000000004 0.20000000000000001<";
  const size_t red = xdmf.find("<Grid Name=\"red\""), green = xdmf.find("<Grid Name=\"green\"");
  ASSERT_NE(red, std::string::npos);
  ASSERT_NE(green, std::string::npos);
  int fields = 0;
  for (size_t at = xdmf.find(field); at != std::string::npos; at = xdmf.find(field, at + 1)) {
    ++fields;
    EXPECT_NE(xdmf.find(values, at), std::string::npos);
    EXPECT_FALSE(at > red && (green < red || at < green)) << "a colour in the red body's block";
  }
  EXPECT_EQ(fields % 2, 0);
  EXPECT_GE(fields, 2 * static_cast<int>(r.time.size()));
}

// A body's thickness is written to its recording's body group and read back with the body
// (issue 40: it was only in the scene JSON): a cloth's default (its contact radius), a set one,
// a volume's 0.
TEST(BodyThickness, RecordedAndReadBack) {
  const std::string json = R"({
    "bodies": [
      {"kind": "cube", "name": "cube", "n": 3, "edge_length": 1, "origin": [-2, 0.5, 0]},
      {"kind": "cloth", "name": "sheet", "nu": 4, "nv": 4, "size_u": 1, "size_v": 1,
       "position": [2, 1, 0]},
      {"kind": "cloth", "name": "thick", "nu": 4, "nv": 4, "size_u": 1, "size_v": 1,
       "position": [4, 1, 0], "thickness": 0.125}
    ],
    "terrains": [], "integrator": {"name": "rk4", "dt": 0.001}, "duration": 0.01
  })";
  const Scene scene = parse_scene(json);
  testing::TempDir dir;
  const std::string path = dir.file("thickness.h5");
  Simulator sim = make_simulator(scene);
  ASSERT_EQ(sim.model().bodies.size(), 3u);
  ASSERT_GT(sim.model().bodies[1].thickness, 0);
  {
    RecorderOptions options;
    options.scene_json = scene_to_json(scene);
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    ASSERT_TRUE(sim.run_until(0.01).ok());
  }
  const Recording r = read_recording(path);
  ASSERT_EQ(r.model.bodies.size(), 3u);
  EXPECT_EQ(r.model.bodies[0].thickness, 0);
  EXPECT_EQ(r.model.bodies[1].thickness, sim.model().bodies[1].thickness);
  EXPECT_EQ(r.model.bodies[1].thickness, sim.model().bodies[1].radius);
  EXPECT_EQ(r.model.bodies[2].thickness, 0.125);
}

TEST(BodyColor, BadColorsNameTheField) {
  for (const std::string color : {"[0.1, 1.5, 0.2]", "[-0.1, 0, 0]", "[0, 0]", "\"green\""}) {
    SCOPED_TRACE(color);
    try {
      load_scene(scene_path("jelly_stack.json"), {"bodies[1].color=" + color});
      FAIL();
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("bodies[1].color"));
    }
  }
  Scene scene = load_scene(scene_path("jelly_stack.json"));
  ASSERT_GE(scene.bodies.size(), 2u);
  scene.bodies[1].color = Vec3(0.5, 2, 0.5);
  try {
    make_simulator(scene);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bodies[1].color"));
    EXPECT_THAT(e.what(), HasSubstr("[0, 1]"));
  }
}

TEST(BodyVelocity, NonFiniteVelocitiesNameTheirField) {
  Scene scene = load_scene(scene_path("seed_slope.json"), {"cube.n=3"});
  scene.bodies[0].angular_velocity = Vec3(0, NAN, 0);
  try {
    make_simulator(scene);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bodies[0].angular_velocity"));
  }
}

}  // namespace
}  // namespace jelly
