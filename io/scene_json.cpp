// Scene <-> JSON: parse_scene and scene_to_json (declared in io/scene.hpp).
#include <cmath>
#include <limits>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/io/detail/scene_override.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/detail/run_fields.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

namespace jelly {

namespace {

// The one-body form of the seed scenes: "cube" and "springs" at the top.
BodySpec read_legacy_cube(JsonFields& root) {
  BodySpec body = Scene::seed_cube_body();
  CubeShape& shape = body.shape.as<CubeShape>();
  if (const Json* c = root.value("cube")) {
    JsonFields f(*c, "cube");
    shape.n = f.integer_or("n", shape.n);
    shape.edge_length = f.number_or("edge_length", shape.edge_length);
    shape.origin = f.vec3_or("origin", shape.origin);
    body.material.particle_mass = f.number_or("particle_mass", body.material.particle_mass);
    f.reject_unknown();
    shape.validate("cube.");
    require(std::isfinite(body.material.particle_mass) && body.material.particle_mass > 0,
            "cube.particle_mass", body.material.particle_mass, "a finite mass > 0");
  }
  if (const Json* sp = root.value("springs")) {
    JsonFields f(*sp, "springs");
    read_springs(f, body.material.springs);
    body.material.validate("");
  }
  return body;
}

Scene scene_from_json(const Json& j, const std::string& base_directory) {
  JsonFields root(j, "");
  Scene s;
  s.description = root.string_or("description", s.description);

  if (const Json* bodies = root.value("bodies")) {
    if (root.has("cube") || root.has("springs")) {
      throw InputError(
          "bodies and cube/springs are both given: a scene with \"bodies\" gives each body's "
          "kind and springs inside it (\"cube\" and \"springs\" are the one-body form)");
    }
    if (!bodies->is_array()) {
      throw InputError("bodies", json_text(*bodies), "a list of bodies [{\"kind\": ...}, ...]");
    }
    s.bodies.clear();
    for (std::size_t i = 0; i < bodies->size(); ++i) {
      JsonFields f((*bodies)[i], json_element("bodies", i));
      f.set_base_directory(base_directory);
      s.bodies.push_back(BodySpec::read(f));
    }
  } else {
    s.bodies = {read_legacy_cube(root)};
  }
  s.gravity = root.vec3_or("gravity", s.gravity);
  s.max_particles = root.long_or("max_particles", s.max_particles);

  if (const Json* ts = root.value("terrains")) {
    if (!ts->is_array()) {
      throw InputError("terrains", json_text(*ts), "a list of terrains [{...}, ...]");
    }
    for (std::size_t i = 0; i < ts->size(); ++i) {
      s.terrains.emplace_back(
          read_terrain_spec((*ts)[i], json_element("terrains", i), base_directory));
    }
  }

  if (const Json* b = root.value("body_contact")) {
    JsonFields f(*b, "body_contact");
    s.body_contact = BodyContactParams::read(f);
  }

  const Json* in = root.value("integrator");
  if (in == nullptr) throw InputError("integrator is missing: it is required ({\"name\": ...})");
  {
    JsonFields f(*in, "integrator");
    s.integrator.name = f.string("name");
    s.integrator.dt = f.number_or("dt", s.integrator.dt);
    find_integrator(s.integrator.name, f.path("name"));
    if (const Json* o = f.value("options")) {
      JsonFields g(*o, f.path("options"));
      s.integrator.options = read_integrator_options(s.integrator.name, g);
      g.reject_unknown();
    }
    f.reject_unknown();
  }

  s.duration = root.number("duration");
  s.output_interval = root.number_or("output_interval", s.output_interval);
  if (const Json* d = root.value("divergence")) {
    JsonFields f(*d, "divergence");
    read_fields(divergence_fields(), f, s.divergence, f.prefix(), /*reject_unknown=*/true);
  }
  if (const Json* c = root.value("crush")) {
    JsonFields f(*c, "crush");
    read_fields(crush_fields(), f, s.crush, f.prefix(), /*reject_unknown=*/true);
  }
  s.threads = root.integer_or("threads", s.threads);
  root.reject_unknown();
  s.validate();
  return s;
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::vector<std::string>& overrides,
                  const std::string& source, const std::string& base_directory) {
  Json j = detail::parse_json(json_text, source);
  for (const std::string& o : overrides) detail::apply_override(j, o);
  return scene_from_json(j, base_directory);
}

std::string scene_to_json(const Scene& s) {
  Json j;
  j["description"] = s.description;
  j["bodies"] = Json::array();
  for (const BodySpec& b : s.bodies) j["bodies"].push_back(b.to_json());
  j["gravity"] = json_of(s.gravity);
  j["max_particles"] = s.max_particles;
  j["terrains"] = Json::array();
  for (const auto& t : s.terrains) j["terrains"].push_back(terrain_spec_json(*t));
  j["body_contact"] = s.body_contact.to_json();
  j["integrator"] = {{"name", s.integrator.name},
                     {"dt", s.integrator.dt},
                     {"options", integrator_options_json(s.integrator.name, s.integrator.options)}};
  j["duration"] = s.duration;
  j["output_interval"] = s.output_interval;
  j["divergence"] = Json::object();
  write_fields(divergence_fields(), s.divergence, j["divergence"]);
  const CrushLimits defaults;
  if (s.crush.min_volume_ratio != defaults.min_volume_ratio ||
      s.crush.max_inverted_fraction != defaults.max_inverted_fraction) {
    j["crush"] = Json::object();
    write_fields(crush_fields(), s.crush, j["crush"]);
  }
  j["threads"] = s.threads;
  return j.dump(2) + "\n";
}

}  // namespace jelly
