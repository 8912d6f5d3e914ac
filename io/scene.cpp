#include <jelly/io/scene.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {

std::string_view terrain_kind_name(TerrainKind kind) {
  switch (kind) {
    case TerrainKind::kPlane:
      return "plane";
    case TerrainKind::kSlope:
      return "slope";
    case TerrainKind::kElevator:
      return "elevator";
  }
  return "unknown";
}

const std::vector<TerrainKind>& terrain_kinds() {
  static const std::vector<TerrainKind> kinds{TerrainKind::kPlane, TerrainKind::kSlope,
                                              TerrainKind::kElevator};
  return kinds;
}

namespace {

void validate_terrain(const TerrainSpec& t, const std::string& prefix) {
  switch (t.kind) {
    case TerrainKind::kPlane:
      require(t.plane.point.allFinite(), prefix + "point", t.plane.point.transpose(),
              "finite coordinates");
      require(t.plane.normal.allFinite() && t.plane.normal.norm() > 1e-12, prefix + "normal",
              t.plane.normal.transpose(), "a finite, non-zero vector");
      break;
    case TerrainKind::kSlope:
      require(std::isfinite(t.slope.angle_degrees) && std::abs(t.slope.angle_degrees) < 90,
              prefix + "angle_degrees", t.slope.angle_degrees, "an angle in (-90, 90) degrees");
      require(t.slope.point.allFinite(), prefix + "point", t.slope.point.transpose(),
              "finite coordinates");
      break;
    case TerrainKind::kElevator:
      t.elevator.validate(prefix);
      break;
  }
  t.contact.validate(prefix + "contact.");
}

SimulatorOptions simulator_options(const Scene& scene) {
  SimulatorOptions options;
  options.dt = scene.integrator.dt;
  options.output_interval = scene.output_interval;
  options.divergence = scene.divergence;
  return options;
}

}  // namespace

void Scene::validate() const {
  cube.validate();  // its field names are the scene's JSON paths: cube.n, springs.shear.kd, ...
  for (std::size_t i = 0; i < terrains.size(); ++i) {
    validate_terrain(terrains[i], "terrains[" + std::to_string(i) + "].");
  }
  const std::vector<std::string> names = integrator_names();
  std::string known;
  for (const std::string& n : names) known += (known.empty() ? "\"" : ", \"") + n + "\"";
  require(std::find(names.begin(), names.end(), integrator.name) != names.end(), "integrator.name",
          "\"" + integrator.name + "\"", "one of " + known);
  integrator.options.validate();
  simulator_options(*this).validate();  // integrator.dt, output_interval, divergence.*
  require(std::isfinite(duration) && duration > 0, "duration", duration, "a finite duration > 0 s");
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_scene(detail::read_json_file(path, "scene file"), overrides, path);
}

std::unique_ptr<Terrain> make_terrain(const TerrainSpec& spec) {
  switch (spec.kind) {
    case TerrainKind::kPlane:
      return std::make_unique<Plane>(spec.plane.point, spec.plane.normal, spec.contact);
    case TerrainKind::kSlope:
      return std::make_unique<Plane>(
          Plane::slope(spec.slope.angle_degrees, spec.slope.point, spec.contact));
    case TerrainKind::kElevator:
      return std::make_unique<Elevator>(spec.elevator, spec.contact);
  }
  throw InputError("terrain.kind", std::to_string(static_cast<int>(spec.kind)), "a TerrainKind");
}

Simulator make_simulator(const Scene& scene) {
  scene.validate();
  Model model = build_cube(scene.cube);
  State state = rest_state(model);
  Simulator sim(std::move(model), std::move(state),
                make_integrator(scene.integrator.name, scene.integrator.options),
                simulator_options(scene));
  for (const TerrainSpec& t : scene.terrains) sim.add_terrain(make_terrain(t));
  return sim;
}

}  // namespace jelly
