#include <jelly/io/scene.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/io/detail/memory_estimate.hpp>
#include <jelly/io/detail/scene_fields.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly {

namespace {

SimulatorOptions simulator_options(const Scene& scene) {
  SimulatorOptions options;
  options.dt = scene.integrator.dt;
  options.output_interval = scene.output_interval;
  options.divergence = scene.divergence;
  options.crush = scene.crush;
  options.threads = scene.threads;
  return options;
}

std::string body_prefix(std::size_t i) { return "bodies[" + std::to_string(i) + "]."; }

}  // namespace

BodySpec cube_body(const CubeSpec& cube, const std::string& name) {
  BodySpec b;
  b.name = name;
  b.shape = cube.shape();
  b.material = cube.material();
  return b;
}

Scene::Scene() : bodies{seed_cube_body()} {}

BodySpec Scene::seed_cube_body() { return cube_body(CubeSpec{}); }

CubeSpec Scene::cube(int index) const {
  require(index >= 0 && index < static_cast<int>(bodies.size()), "bodies", index,
          "the index of a body of the scene");
  const BodySpec& b = bodies[index];
  require(b.shape && b.shape.is<CubeShape>(), body_prefix(index) + "kind",
          "\"" + std::string(b.kind()) + "\"", "\"cube\"");
  const CubeShape& s = b.shape.as<CubeShape>();
  CubeSpec c;
  c.n = s.n;
  c.edge_length = s.edge_length;
  c.origin = s.origin;
  c.particle_mass = b.material.particle_mass;
  c.springs = b.material.springs;
  c.gravity = gravity;
  return c;
}

void Scene::set_cube(const CubeSpec& cube, int index) {
  require(index >= 0 && index < static_cast<int>(bodies.size()), "bodies", index,
          "the index of a body of the scene");
  const std::string name = bodies[index].name;
  const Real radius = bodies[index].radius;
  const std::optional<Real> thickness = bodies[index].thickness;
  std::vector<PinSpec> pins = std::move(bodies[index].pins);
  std::vector<ExternalForceSpec> forces = std::move(bodies[index].forces);
  bodies[index] = cube_body(cube, name);
  bodies[index].radius = radius;
  bodies[index].thickness = thickness;
  bodies[index].pins = std::move(pins);
  bodies[index].forces = std::move(forces);
  gravity = cube.gravity;
}

void Scene::validate() const {
  require(!bodies.empty(), "bodies", "[]", "at least one body");
  long particles = 0, springs = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    bodies[i].validate(body_prefix(i));
    for (std::size_t j = 0; j < i; ++j) {
      require(bodies[j].name != bodies[i].name, body_prefix(i) + "name",
              "\"" + bodies[i].name + "\"",
              "a name no other body has (bodies[" + std::to_string(j) + "] has it)");
    }
    particles += bodies[i].shape->estimated_particles();
    springs += bodies[i].shape->estimated_springs();
  }
  // gravity, max_particles, duration, output_interval, threads (the other rows are objects).
  validate_fields(scene_fields(), *this, "");
  require(particles <= max_particles, "bodies", std::to_string(particles) + " particles",
          "at most max_particles = " + std::to_string(max_particles) + " (they would need about " +
              bytes_text(estimate_memory_bytes(particles, springs, integrator.name, false)) +
              " of memory with " + integrator.name + "; raise max_particles if it allows)");
  for (std::size_t i = 0; i < terrains.size(); ++i) {
    const std::string prefix = "terrains[" + std::to_string(i) + "].";
    require(static_cast<bool>(terrains[i]), prefix + "kind", "none", "a terrain kind");
    terrains[i]->validate(prefix);
    terrains[i]->contact.validate(prefix + "contact.");
  }
  body_contact.validate("body_contact.");
  const IntegratorInfo& info = find_integrator(integrator.name, "integrator.name");
  if (info.options.validate) info.options.validate(integrator.options, "integrator.options.");
  validate_fields(integrator_spec_fields(), integrator, "integrator.");
  simulator_options(*this).validate();  // divergence.*, crush.*
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_scene(detail::read_json_file(path, "scene file"), overrides, path,
                     std::filesystem::path(path).parent_path().string());
}

std::unique_ptr<Terrain> make_terrain(const TerrainSpec& spec) { return spec.make(); }

Model make_model(const Scene& scene) {
  scene.validate();
  Model model;
  model.gravity = scene.gravity;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    add_body(model, scene.bodies[i], body_prefix(i));
  }
  return model;
}

Simulator make_simulator(const Scene& scene) {
  Model model = make_model(scene);
  State state = initial_state(model);
  Simulator sim(std::move(model), std::move(state),
                make_integrator(scene.integrator.name, scene.integrator.options),
                simulator_options(scene));
  for (const auto& t : scene.terrains) sim.add_terrain(t->make());
  sim.set_body_contact(scene.body_contact);
  sim.check_no_overlap();  // bodies that start inside each other: an error naming both
  return sim;
}

}  // namespace jelly
