// Scene <-> JSON: parse_scene and scene_to_json (declared in io/scene.hpp).
#include <cmath>
#include <limits>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/integrator_options_json.hpp>
#include <jelly/io/detail/json_fields.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/io/detail/scene_override.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {

namespace {

using detail::Json;
using detail::json_element;
using detail::JsonFields;

constexpr const char* kSpringKeys[kSpringTypeCount] = {"structural", "shear", "bending"};

Json vec3_json(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

ContactParams parse_contact(const Json& j, const std::string& path) {
  JsonFields f(j, path);
  ContactParams c;
  c.model = contact_model_from_name(f.string_or("model", std::string(contact_model_name(c.model))),
                                    f.path("model"));
  c.restitution = f.number_or("restitution", c.restitution);
  c.friction = f.number_or("friction", c.friction);
  c.static_friction = f.number_or("static_friction", c.static_friction);
  c.epsilon = f.number_or("epsilon", c.epsilon);
  c.resting_speed = f.number_or("resting_speed", c.resting_speed);
  f.reject_unknown();
  c.validate(path + ".");
  return c;
}

ElevatorMotion parse_motion(const Json& j, const std::string& path) {
  if (j.is_string() && j.get<std::string>() == "seed") return ElevatorMotion::seed();
  if (!j.is_array()) {
    throw InputError(path, detail::json_text(j),
                     "\"seed\" or a list of phases [{\"duration\": 2, \"acceleration\": 3, "
                     "\"stop_at_end\": true}, ...]");
  }
  std::vector<MotionPhase> phases;
  for (std::size_t i = 0; i < j.size(); ++i) {
    JsonFields f(j[i], json_element(path, i));
    MotionPhase p;
    p.duration = f.number("duration");
    p.acceleration = f.number("acceleration");
    p.stop_at_end = f.boolean_or("stop_at_end", p.stop_at_end);
    f.reject_unknown();
    phases.push_back(p);
  }
  return ElevatorMotion(std::move(phases), path);
}

Real parse_mass(const Json& j, const std::string& path) {
  if (j.is_string() && j.get<std::string>() == "inf") return std::numeric_limits<Real>::infinity();
  if (!j.is_number()) throw InputError(path, detail::json_text(j), "a number or \"inf\"");
  return j.get<Real>();
}

TerrainSpec parse_terrain(const Json& j, const std::string& path) {
  JsonFields f(j, path);
  TerrainSpec t;
  const std::string kind = f.string("kind");
  std::string kinds;
  bool found = false;
  for (TerrainKind k : terrain_kinds()) {
    kinds += (kinds.empty() ? "\"" : ", \"") + std::string(terrain_kind_name(k)) + "\"";
    if (terrain_kind_name(k) == kind) t.kind = k, found = true;
  }
  if (!found) throw InputError(f.path("kind"), "\"" + kind + "\"", "one of " + kinds);
  switch (t.kind) {
    case TerrainKind::kPlane:
      t.plane.point = f.vec3_or("point", t.plane.point);
      t.plane.normal = f.vec3_or("normal", t.plane.normal);
      break;
    case TerrainKind::kSlope:
      t.slope.angle_degrees = f.number_or("angle_degrees", t.slope.angle_degrees);
      t.slope.point = f.vec3_or("point", t.slope.point);
      break;
    case TerrainKind::kElevator: {
      ElevatorSpec& e = t.elevator;
      e.center = f.vec3_or("center", e.center);
      e.size_x = f.number_or("size_x", e.size_x);
      e.size_z = f.number_or("size_z", e.size_z);
      e.thickness = f.number_or("thickness", e.thickness);
      if (const Json* m = f.value("mass")) e.mass = parse_mass(*m, f.path("mass"));
      if (const Json* m = f.value("motion")) e.motion = parse_motion(*m, f.path("motion"));
      break;
    }
  }
  if (const Json* c = f.value("contact")) t.contact = parse_contact(*c, f.path("contact"));
  f.reject_unknown();
  return t;
}

Scene scene_from_json(const Json& j) {
  JsonFields root(j, "");
  Scene s;
  s.description = root.string_or("description", s.description);

  if (const Json* c = root.value("cube")) {
    JsonFields f(*c, "cube");
    s.cube.n = f.integer_or("n", s.cube.n);
    s.cube.edge_length = f.number_or("edge_length", s.cube.edge_length);
    s.cube.origin = f.vec3_or("origin", s.cube.origin);
    s.cube.particle_mass = f.number_or("particle_mass", s.cube.particle_mass);
    f.reject_unknown();
  }
  if (const Json* sp = root.value("springs")) {
    JsonFields f(*sp, "springs");
    for (int t = 0; t < kSpringTypeCount; ++t) {
      if (const Json* one = f.value(kSpringKeys[t])) {
        JsonFields g(*one, f.path(kSpringKeys[t]));
        s.cube.springs[t].ks = g.number_or("ks", s.cube.springs[t].ks);
        s.cube.springs[t].kd = g.number_or("kd", s.cube.springs[t].kd);
        g.reject_unknown();
      }
    }
    f.reject_unknown();
  }
  s.cube.gravity = root.vec3_or("gravity", s.cube.gravity);

  if (const Json* ts = root.value("terrains")) {
    if (!ts->is_array()) {
      throw InputError("terrains", detail::json_text(*ts), "a list of terrains [{...}, ...]");
    }
    for (std::size_t i = 0; i < ts->size(); ++i) {
      s.terrains.push_back(parse_terrain((*ts)[i], json_element("terrains", i)));
    }
  }

  const Json* in = root.value("integrator");
  if (in == nullptr) throw InputError("integrator is missing: it is required ({\"name\": ...})");
  {
    JsonFields f(*in, "integrator");
    s.integrator.name = f.string("name");
    s.integrator.dt = f.number_or("dt", s.integrator.dt);
    if (const Json* o = f.value("options")) {
      s.integrator.options =
          detail::parse_integrator_options(*o, f.path("options"), s.integrator.name);
    }
    f.reject_unknown();
  }

  s.duration = root.number("duration");
  s.output_interval = root.number_or("output_interval", s.output_interval);
  if (const Json* d = root.value("divergence")) {
    JsonFields f(*d, "divergence");
    s.divergence.max_speed = f.number_or("max_speed", s.divergence.max_speed);
    s.divergence.max_distance = f.number_or("max_distance", s.divergence.max_distance);
    f.reject_unknown();
  }
  root.reject_unknown();
  s.validate();
  return s;
}

Json contact_json(const ContactParams& c) {
  Json j;
  j["model"] = std::string(contact_model_name(c.model));
  j["restitution"] = c.restitution;
  j["friction"] = c.friction;
  j["static_friction"] = c.static_friction;
  j["epsilon"] = c.epsilon;
  j["resting_speed"] = c.resting_speed;
  return j;
}

Json terrain_json(const TerrainSpec& t) {
  Json j;
  j["kind"] = std::string(terrain_kind_name(t.kind));
  switch (t.kind) {
    case TerrainKind::kPlane:
      j["point"] = vec3_json(t.plane.point);
      j["normal"] = vec3_json(t.plane.normal);
      break;
    case TerrainKind::kSlope:
      j["angle_degrees"] = t.slope.angle_degrees;
      j["point"] = vec3_json(t.slope.point);
      break;
    case TerrainKind::kElevator: {
      const ElevatorSpec& e = t.elevator;
      j["center"] = vec3_json(e.center);
      j["size_x"] = e.size_x;
      j["size_z"] = e.size_z;
      j["thickness"] = e.thickness;
      j["mass"] = std::isinf(e.mass) ? Json("inf") : Json(e.mass);
      Json motion = Json::array();
      for (const MotionPhase& p : e.motion.phases()) {
        motion.push_back({{"duration", p.duration},
                          {"acceleration", p.acceleration},
                          {"stop_at_end", p.stop_at_end}});
      }
      j["motion"] = motion;
      break;
    }
  }
  j["contact"] = contact_json(t.contact);
  return j;
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::vector<std::string>& overrides,
                  const std::string& source) {
  Json j = detail::parse_json(json_text, source);
  for (const std::string& o : overrides) detail::apply_override(j, o);
  return scene_from_json(j);
}

std::string scene_to_json(const Scene& s) {
  Json j;
  j["description"] = s.description;
  j["cube"] = {{"n", s.cube.n},
               {"edge_length", s.cube.edge_length},
               {"origin", vec3_json(s.cube.origin)},
               {"particle_mass", s.cube.particle_mass}};
  Json springs;
  for (int t = 0; t < kSpringTypeCount; ++t) {
    springs[kSpringKeys[t]] = {{"ks", s.cube.springs[t].ks}, {"kd", s.cube.springs[t].kd}};
  }
  j["springs"] = springs;
  j["gravity"] = vec3_json(s.cube.gravity);
  j["terrains"] = Json::array();
  for (const TerrainSpec& t : s.terrains) j["terrains"].push_back(terrain_json(t));
  j["integrator"] = {
      {"name", s.integrator.name},
      {"dt", s.integrator.dt},
      {"options", detail::integrator_options_to_json(s.integrator.options, s.integrator.name)}};
  j["duration"] = s.duration;
  j["output_interval"] = s.output_interval;
  j["divergence"] = {{"max_speed", s.divergence.max_speed},
                     {"max_distance", s.divergence.max_distance}};
  return j.dump(2) + "\n";
}

}  // namespace jelly
