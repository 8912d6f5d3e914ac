// Scene <-> JSON: parse_scene and scene_to_json (declared in io/scene.hpp).
#include <cmath>
#include <limits>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/io/detail/scene_fields.hpp>
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

// An object row written only when not `is_default`.
Field<Scene> omitted_when_default(Field<Scene> f, bool (*is_default)(const Scene&)) {
  f.is_default = is_default;
  f.omit_default = true;
  return f;
}

void read_scene_divergence(JsonFields& root, Scene& s, std::string_view key) {
  if (const Json* d = root.value(key)) {
    JsonFields f(*d, root.path(key));
    read_fields(divergence_fields(), f, s.divergence, f.prefix(), /*reject_unknown=*/true);
  }
}

void read_scene_crush(JsonFields& root, Scene& s, std::string_view key) {
  if (const Json* c = root.value(key)) {
    JsonFields f(*c, root.path(key));
    read_fields(crush_fields(), f, s.crush, f.prefix(), /*reject_unknown=*/true);
  }
}

}  // namespace

const FieldTable<IntegratorSpec>& integrator_spec_fields() {
  using I = IntegratorSpec;
  static const FieldTable<I> table{
      "IntegratorSpec",
      "integrator",
      "The time integration method, its step and options",
      {
          object_field<I>(
              "name", FieldType::kString, "a name from `jelly list` (integrator lines)",
              "The method (required)", "",
              [](JsonFields& f, I& s, std::string_view key) {
                s.name = f.string(key);
                find_integrator(s.name, f.path(key));
              },
              [](const I& s, Json& j, std::string_view key) { j[std::string(key)] = s.name; }),
          time_step_field<&I::dt>(),
          object_field<I>(
              "options", FieldType::kObject, "the method's options (its own table)",
              "Options of the method: integrator.options of its name", R"({})",
              [](JsonFields& f, I& s, std::string_view key) {
                if (const Json* o = f.value(key)) {
                  JsonFields g(*o, f.path(key));
                  s.options = read_integrator_options(s.name, g);
                  g.reject_unknown();
                }
              },
              [](const I& s, Json& j, std::string_view key) {
                j[std::string(key)] = integrator_options_json(s.name, s.options);
              }),
      },
  };
  return table;
}

const FieldTable<Scene>& scene_fields() {
  static const FieldTable<Scene> table{
      "Scene",
      "",
      "A scene's top-level keys",
      {
          string_field<&Scene::description>("description", "any text",
                                            "Free text, not used by the solver"),
          object_field<Scene>(
              "bodies", FieldType::kList,
              "a list of bodies [{\"kind\": ...}, ...] (each: bodies[i] and its kind's table)",
              "The bodies, in order; without it, \"cube\" and \"springs\" give one cube",
              R"([{"name": "jelly", "kind": "cube", "n": 3}])",
              [](JsonFields& root, Scene& s, std::string_view key) {
                if (const Json* bodies = root.value(key)) {
                  if (root.has("cube") || root.has("springs")) {
                    throw InputError(
                        "bodies and cube/springs are both given: a scene with \"bodies\" gives "
                        "each body's kind and springs inside it (\"cube\" and \"springs\" are "
                        "the one-body form)");
                  }
                  if (!bodies->is_array()) {
                    throw InputError("bodies", json_text(*bodies),
                                     "a list of bodies [{\"kind\": ...}, ...]");
                  }
                  s.bodies.clear();
                  for (std::size_t i = 0; i < bodies->size(); ++i) {
                    JsonFields f((*bodies)[i], json_element("bodies", i));
                    f.set_base_directory(root.base_directory());
                    s.bodies.push_back(BodySpec::read(f));
                  }
                } else {
                  s.bodies = {read_legacy_cube(root)};
                }
              },
              [](const Scene& s, Json& j, std::string_view key) {
                Json list = Json::array();
                for (const BodySpec& b : s.bodies) list.push_back(b.to_json());
                j[std::string(key)] = list;
              }),
          vec3_field<&Scene::gravity>("gravity", "m/s^2", range_finite(), "finite components",
                                      "Acceleration of gravity"),
          integer_field<&Scene::max_particles>(
              "max_particles", "", range_above(0), "a number of particles > 0",
              "Most particles the bodies may have together (a guard against exhausting memory)"),
          object_field<Scene>(
              "terrains", FieldType::kList,
              "a list of terrains [{\"kind\": ..., \"contact\": ...}, ...] (each: its kind's "
              "table)",
              "Terrains and obstacles, each with its contact model",
              R"([{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], )"
              R"("contact": {"model": "coulomb", "restitution": 0.5, "friction": 0.3, )"
              R"("static_friction": 0.3, "epsilon": 0.001, "resting_speed": 0.0}}])",
              [](JsonFields& root, Scene& s, std::string_view key) {
                if (const Json* ts = root.value(key)) {
                  if (!ts->is_array()) {
                    throw InputError("terrains", json_text(*ts), "a list of terrains [{...}, ...]");
                  }
                  for (std::size_t i = 0; i < ts->size(); ++i) {
                    s.terrains.emplace_back(read_terrain_spec((*ts)[i], json_element("terrains", i),
                                                              root.base_directory()));
                  }
                }
              },
              [](const Scene& s, Json& j, std::string_view key) {
                Json list = Json::array();
                for (const auto& t : s.terrains) list.push_back(terrain_spec_json(*t));
                j[std::string(key)] = list;
              }),
          object_field<Scene>(
              "body_contact", FieldType::kObject, "a BodyContactParams object (its own table)",
              "Contact between bodies (docs/contact.md)", "",
              [](JsonFields& root, Scene& s, std::string_view key) {
                if (const Json* b = root.value(key)) {
                  JsonFields f(*b, root.path(key));
                  s.body_contact = BodyContactParams::read(f);
                }
              },
              [](const Scene& s, Json& j, std::string_view key) {
                j[std::string(key)] = s.body_contact.to_json();
              }),
          object_field<Scene>(
              "integrator", FieldType::kObject,
              "an object {name, dt, options} (required; its own table)",
              "The time integration method", "",
              [](JsonFields& root, Scene& s, std::string_view key) {
                const Json* in = root.value(key);
                if (in == nullptr) {
                  throw InputError("integrator is missing: it is required ({\"name\": ...})");
                }
                JsonFields f(*in, root.path(key));
                read_fields(integrator_spec_fields(), f, s.integrator, f.prefix(),
                            /*reject_unknown=*/true);
              },
              [](const Scene& s, Json& j, std::string_view key) {
                j[std::string(key)] = Json::object();
                write_fields(integrator_spec_fields(), s.integrator, j[std::string(key)]);
              }),
          required(number_field<&Scene::duration>("duration", "s", range_above(0),
                                                  "a finite duration > 0 s",
                                                  "Time `jelly run` simulates")),
          output_interval_field<&Scene::output_interval>(),
          object_field<Scene>(
              "divergence", FieldType::kObject, "a DivergenceGuard object (its own table)",
              "What counts as diverged", "", read_scene_divergence,
              [](const Scene& s, Json& j, std::string_view key) {
                j[std::string(key)] = Json::object();
                write_fields(divergence_fields(), s.divergence, j[std::string(key)]);
              }),
          omitted_when_default(
              object_field<Scene>(
                  "crush", FieldType::kObject, "a CrushLimits object (its own table)",
                  "When a run's end names a crushed body (written when not the defaults)", "",
                  read_scene_crush,
                  [](const Scene& s, Json& j, std::string_view key) {
                    j[std::string(key)] = Json::object();
                    write_fields(crush_fields(), s.crush, j[std::string(key)]);
                  }),
              [](const Scene& s) {
                const CrushLimits d;
                return s.crush.min_volume_ratio == d.min_volume_ratio &&
                       s.crush.max_inverted_fraction == d.max_inverted_fraction;
              }),
          threads_field<&Scene::threads>(),
      },
  };
  return table;
}

namespace {

Scene scene_from_json(const Json& j, const std::string& base_directory) {
  JsonFields root(j, "");
  root.set_base_directory(base_directory);
  Scene s;
  read_fields(scene_fields(), root, s, "", /*reject_unknown=*/true);
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
  Json j = Json::object();
  write_fields(scene_fields(), s, j);
  return j.dump(2) + "\n";
}

}  // namespace jelly
