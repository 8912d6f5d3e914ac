#pragma once
// A scene: everything a run needs (cube, springs, gravity, terrains with their contact, the
// integrator, duration, output interval, divergence limits), read from and written to JSON with
// strict validation. The JSON format is described in docs/scenes.md.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/cube.hpp>
#include <jelly/solvers/divergence_guard.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/contact_params.hpp>
#include <jelly/terrain/elevator.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

enum class TerrainKind { kPlane, kSlope, kElevator };
std::string_view terrain_kind_name(TerrainKind kind);
// Every terrain kind a scene can name, in the order of TerrainKind.
const std::vector<TerrainKind>& terrain_kinds();

// A fixed plane through `point` with outward normal `normal` (need not be unit length).
struct PlaneSpec {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
};

// A plane through `point` tilted by `angle_degrees` about z: normal (sin a, cos a, 0).
struct SlopeSpec {
  Real angle_degrees = 20;
  Vec3 point = Vec3::Zero();
};

// One terrain of a scene: only the spec that matches `kind` is used.
struct TerrainSpec {
  TerrainKind kind = TerrainKind::kPlane;
  PlaneSpec plane;
  SlopeSpec slope;
  ElevatorSpec elevator;
  ContactParams contact;
};

struct IntegratorSpec {
  std::string name;  // a name from integrator_names(); required in a scene file
  Real dt = 0.001;   // s
  IntegratorOptions options;
};

struct Scene {
  std::string description;  // free text, not used by the solver
  CubeSpec cube;            // the lattice, the springs of each type and gravity
  std::vector<TerrainSpec> terrains;
  IntegratorSpec integrator;
  Real duration = 5;                // s simulated by `jelly run`; required in a scene file
  Real output_interval = 1.0 / 60;  // s between recorded frames; 0 = every step
  DivergenceGuard divergence;

  // Throws InputError naming the JSON path of the first invalid field (e.g.
  // "terrains[0].contact.restitution"), its value and what is allowed.
  void validate() const;
};

// Reads and validates a scene file, applying `overrides` ("springs.structural.ks=2400", see
// apply_override) to the JSON before it is validated. Throws InputError for a file that cannot
// be read, is not JSON, or holds an invalid scene.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});
// The same from JSON text; `source` names the text in messages (a file name).
Scene parse_scene(const std::string& json_text, const std::vector<std::string>& overrides = {},
                  const std::string& source = "scene");
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
// The cube at rest, its terrains, the named integrator and the simulator options of the scene.
// The caller runs it: sim.run_until(scene.duration).
Simulator make_simulator(const Scene& scene);

}  // namespace jelly
