#pragma once
// A scene: everything a run needs (bodies with their materials, pins and forces, gravity,
// terrains with their contact, the integrator, duration, output interval, divergence limits),
// read from and written to JSON with strict validation. The JSON format is in docs/scenes.md.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/polymorphic_value.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/run_report.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

namespace jelly {

// The integrator of a scene: its name, step and options.
struct IntegratorSpec {
  std::string name;           // a name from integrator_names(); required in a scene file
  Real dt = 0.001;            // s
  IntegratorOptions options;  // the options of every method (only the named one's are used)
};

// A scene: bodies, terrains, gravity, contact, integrator, duration and output, as a scene file
// holds them (docs/scenes.md).
struct Scene {
  std::string description;  // free text, not used by the solver
  // The bodies, in order (their particles follow each other in the model). A scene file
  // without "bodies" holds one cube named "jelly" described by its "cube" and "springs" keys.
  std::vector<BodySpec> bodies;                         // Scene(): {seed_cube_body()}
  Vec3 gravity{0, -9.8, 0};                             // m/s^2
  std::vector<PolymorphicValue<TerrainSpec>> terrains;  // terrains and obstacles, in order
  // Contact between bodies (and, with self_contact, within a body): docs/contact.md.
  BodyContactParams body_contact;
  IntegratorSpec integrator;        // the integrator, its step and options
  Real duration = 5;                // s simulated by `jelly run`; required in a scene file
  Real output_interval = 1.0 / 60;  // s between recorded frames; 0 = every step
  DivergenceGuard divergence;       // when a run counts as diverged
  // When a run reports a body crushed (solvers/run_report.hpp; key "crush"; written only when
  // not the defaults).
  CrushLimits crush{};
  // Most particles the bodies may have together (a guard against a spacing or n that would
  // exhaust memory).
  long max_particles = 2'000'000;
  // Threads for the force loop, the solves and contact (0 = all cores); the results are the
  // same bit for bit for any number (docs/threads.md). `jelly run --threads` overrides it.
  int threads = 0;

  // The defaults: one body, seed_cube_body(). Out of line, so that includers do not compile the
  // list's construction.
  Scene();

  // Throws InputError naming the JSON path of the first invalid field (e.g.
  // "terrains[0].contact.restitution"), its value and what is allowed.
  void validate() const;

  // The seed's cube body: CubeSpec{} as body "jelly".
  static BodySpec seed_cube_body();
  // A scene's cube body as a CubeSpec with the scene's gravity (one-cube scenes, tests); throws
  // InputError when body `index` is not a cube.
  CubeSpec cube(int index = 0) const;
  // Replaces body `index` by `cube` and sets the scene's gravity to the cube's.
  void set_cube(const CubeSpec& cube, int index = 0);
};

// A body of kind "cube" from a CubeSpec (its gravity is the scene's, not the body's).
BodySpec cube_body(const CubeSpec& cube, const std::string& name = "jelly");

// Reads and validates a scene file, applying `overrides` ("springs.structural.ks=2400", see
// apply_override) to the JSON before it is validated. Throws InputError for a file that cannot
// be read, is not JSON, or holds an invalid scene.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});
// The same from JSON text; `source` names the text in messages (a file name). Files the
// scene names (a body's mesh) are relative to `base_directory` ("" = the current directory;
// load_scene passes the scene file's folder); the scene holds them as absolute paths.
Scene parse_scene(const std::string& json_text, const std::vector<std::string>& overrides = {},
                  const std::string& source = "scene", const std::string& base_directory = "");
// The scene as pretty-printed JSON with every field written out; parse_scene reads it back to
// an equal scene.
std::string scene_to_json(const Scene& scene);

// Applies one assignment "path=value" to scene JSON text and returns the new text. The path is
// dotted, array elements by index: "terrains.0.contact.restitution" or
// "terrains[0].contact.restitution". The value is parsed as JSON if it parses, else taken as a
// string ("integrator.name=rk4"). Missing object keys along the path are created (the scene
// validation then rejects unknown ones); a missing array element or a path through a number is
// an InputError.
std::string apply_override(const std::string& json_text, const std::string& assignment);

// The terrain a spec describes, with its contact parameters.
std::unique_ptr<Terrain> make_terrain(const TerrainSpec& spec);
// The scene's model: its bodies (with pins and external forces) and gravity.
Model make_model(const Scene& scene);
// The bodies at rest, the terrains, the named integrator and the simulator options of the
// scene. The caller runs it: sim.run_until(scene.duration).
Simulator make_simulator(const Scene& scene);

}  // namespace jelly
