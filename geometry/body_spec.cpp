#include <jelly/geometry/body_spec.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_shape.hpp>

namespace jelly {

namespace {

constexpr const char* kSpringKeys[kSpringTypeCount] = {"structural", "shear", "bending"};

}  // namespace

void read_springs(JsonFields& f, std::array<SpringCoefficients, kSpringTypeCount>& springs) {
  for (int t = 0; t < kSpringTypeCount; ++t) {
    if (const Json* one = f.value(kSpringKeys[t])) {
      JsonFields g(*one, f.path(kSpringKeys[t]));
      springs[t].ks = g.number_or("ks", springs[t].ks);
      springs[t].kd = g.number_or("kd", springs[t].kd);
      g.reject_unknown();
    }
  }
  f.reject_unknown();
}

Json springs_json(const std::array<SpringCoefficients, kSpringTypeCount>& springs) {
  Json j;
  for (int t = 0; t < kSpringTypeCount; ++t) {
    j[kSpringKeys[t]] = {{"ks", springs[t].ks}, {"kd", springs[t].kd}};
  }
  return j;
}

std::vector<int> ParticleSelection::resolve(const Model& model, const Body& body,
                                            const std::string& prefix) const {
  std::vector<int> out;
  if (selects_all()) {
    for (int i = body.first_particle; i < body.end_particle(); ++i) out.push_back(i);
    return out;
  }
  for (int i : indices) {
    require(i >= 0 && i < body.num_particles, prefix + "indices", i,
            "particle indices of body \"" + body.name + "\" in [0, " +
                std::to_string(body.num_particles) + ")");
    out.push_back(body.first_particle + i);
  }
  if (has_region) {
    int found = 0;
    for (int i = body.first_particle; i < body.end_particle(); ++i) {
      if (region.contains(particle(model.rest_position, i))) {
        out.push_back(i);
        ++found;
      }
    }
    require(found > 0, prefix + "region",
            "{min: [" + to_text(region.min().transpose()) + "], max: [" +
                to_text(region.max().transpose()) + "]}",
            "a box holding at least one particle of body \"" + body.name + "\" at rest");
  }
  if (!group.empty()) {
    const auto g = std::find_if(body.groups.begin(), body.groups.end(),
                                [&](const ParticleGroup& pg) { return pg.name == group; });
    std::string known;
    for (const ParticleGroup& pg : body.groups) known += (known.empty() ? "" : ", ") + pg.name;
    require(g != body.groups.end() && !g->particles.empty(), prefix + "group", "\"" + group + "\"",
            known.empty() ? "a group of the body (this body has none)"
                          : "a group of the body: one of " + known);
    out.insert(out.end(), g->particles.begin(), g->particles.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

ParticleSelection ParticleSelection::read(JsonFields& f) {
  ParticleSelection s;
  if (const Json* idx = f.value("indices")) {
    if (!idx->is_array() || idx->empty()) {
      throw InputError(f.path("indices"), json_text(*idx),
                       "a list of at least one particle index (leave \"indices\", \"region\" "
                       "and \"group\" out to choose the whole body)");
    }
    for (std::size_t i = 0; i < idx->size(); ++i) {
      s.indices.push_back(json_integer((*idx)[i], json_element(f.path("indices"), i)));
    }
  }
  if (const Json* r = f.value("region")) {
    JsonFields g(*r, f.path("region"));
    const Vec3 lo = json_vec3(g.value("min") ? *g.value("min") : Json(), g.path("min"));
    const Vec3 hi = json_vec3(g.value("max") ? *g.value("max") : Json(), g.path("max"));
    g.reject_unknown();
    require((lo.array() <= hi.array()).all(), g.path("max"), hi.transpose(),
            "a corner >= min in every coordinate");
    s.has_region = true;
    s.region = Eigen::AlignedBox3d(lo, hi);
  }
  s.group = f.string_or("group", "");
  return s;
}

void ParticleSelection::write(Json& j) const {
  if (!indices.empty()) j["indices"] = indices;
  if (has_region) {
    j["region"] = {{"min", json_of(region.min())}, {"max", json_of(region.max())}};
  }
  if (!group.empty()) j["group"] = group;
}

void BodySpec::validate(const std::string& prefix) const {
  require(!name.empty(), prefix + "name", "\"\"", "a non-empty name");
  require(name.find_first_of("/.") == std::string::npos, prefix + "name", "\"" + name + "\"",
          "a name without '/' or '.' (it names an HDF5 group)");
  require(static_cast<bool>(shape), prefix + "kind", "none", "a body kind");
  shape->validate(prefix);
  material.validate(prefix);
  require(std::isfinite(radius) && radius >= 0, prefix + "radius", radius,
          "a finite radius >= 0 m (0 = half the lattice spacing)");
  if (thickness) {
    require(std::isfinite(*thickness) && *thickness >= 0, prefix + "thickness", *thickness,
            "a finite distance >= 0 m (the default: the contact radius for a cloth, 0 for a body "
            "with volume)");
  }
  require(velocity.allFinite(), prefix + "velocity", velocity.transpose(),
          "finite components (m/s)");
  require(angular_velocity.allFinite(), prefix + "angular_velocity", angular_velocity.transpose(),
          "finite components (rad/s)");
  if (color) {
    require(color->allFinite() && color->minCoeff() >= 0 && color->maxCoeff() <= 1,
            prefix + "color", color->transpose(), "[r, g, b], each in [0, 1]");
  }
}

BodySpec BodySpec::read(JsonFields& f) {
  BodySpec b;
  const std::string kind = f.string("kind");
  b.name = f.string_or("name", b.name);
  b.shape = find_body_kind(kind, f.path("kind")).read(f);
  if (const Json* sp = f.value("springs")) {
    JsonFields g(*sp, f.path("springs"));
    read_springs(g, b.material.springs);
  }
  b.material.particle_mass = f.number_or("particle_mass", b.material.particle_mass);
  b.material.density = f.number_or("density", b.material.density);
  b.radius = f.number_or("radius", b.radius);
  if (f.value("thickness")) b.thickness = f.number("thickness");
  b.velocity = f.vec3_or("velocity", b.velocity);
  b.angular_velocity = f.vec3_or("angular_velocity", b.angular_velocity);
  if (const Json* color = f.value("color")) b.color = json_vec3(*color, f.path("color"));
  if (const Json* pins = f.value("pins")) {
    if (!pins->is_array()) throw InputError(f.path("pins"), json_text(*pins), "a list of pins");
    for (std::size_t i = 0; i < pins->size(); ++i) {
      JsonFields g((*pins)[i], json_element(f.path("pins"), i));
      PinSpec pin;
      pin.select = ParticleSelection::read(g);
      if (const Json* p = g.value("path")) pin.path = Path::read(*p, g.path("path"));
      g.reject_unknown();
      b.pins.push_back(std::move(pin));
    }
  }
  if (const Json* forces = f.value("forces")) {
    if (!forces->is_array()) {
      throw InputError(f.path("forces"), json_text(*forces), "a list of external forces");
    }
    for (std::size_t i = 0; i < forces->size(); ++i) {
      JsonFields g((*forces)[i], json_element(f.path("forces"), i));
      ExternalForceSpec e;
      e.kind = external_force_kind_from_name(g.string("kind"), g.path("kind"));
      e.select = ParticleSelection::read(g);
      if (e.kind == ExternalForceKind::kWind) {
        e.vector = g.vec3_or("velocity", e.vector);
        e.drag = g.number("drag");
      } else {
        e.vector = g.vec3_or("force", e.vector);
      }
      e.gust = g.number_or("gust", e.gust);
      e.gust_frequency = g.number_or("gust_frequency", e.gust_frequency);
      e.start = g.number_or("start", e.start);
      if (const Json* end = g.value("end")) {
        e.end = (end->is_string() && end->get<std::string>() == "inf")
                    ? std::numeric_limits<Real>::infinity()
                    : json_number(*end, g.path("end"));
      }
      g.reject_unknown();
      b.forces.push_back(std::move(e));
    }
  }
  f.reject_unknown();
  b.validate(f.prefix());
  return b;
}

Json BodySpec::to_json() const {
  Json j;
  j["name"] = name;
  j["kind"] = std::string(kind());
  shape->write(j);
  j["springs"] = springs_json(material.springs);
  j["particle_mass"] = material.particle_mass;
  j["density"] = material.density;
  j["radius"] = radius;
  if (thickness) j["thickness"] = *thickness;
  if (!velocity.isZero()) j["velocity"] = json_of(velocity);
  if (!angular_velocity.isZero()) j["angular_velocity"] = json_of(angular_velocity);
  if (color) j["color"] = json_of(*color);
  if (!pins.empty()) {
    Json list = Json::array();
    for (const PinSpec& p : pins) {
      Json pj;
      p.select.write(pj);
      if (!p.path.is_fixed()) pj["path"] = p.path.to_json();
      list.push_back(pj);
    }
    j["pins"] = list;
  }
  if (!forces.empty()) {
    Json list = Json::array();
    for (const ExternalForceSpec& e : forces) {
      Json fj;
      fj["kind"] = std::string(external_force_kind_name(e.kind));
      e.select.write(fj);
      if (e.kind == ExternalForceKind::kWind) {
        fj["velocity"] = json_of(e.vector);
        fj["drag"] = e.drag;
      } else {
        fj["force"] = json_of(e.vector);
      }
      fj["gust"] = e.gust;
      fj["gust_frequency"] = e.gust_frequency;
      fj["start"] = e.start;
      fj["end"] = std::isinf(e.end) ? Json("inf") : Json(e.end);
      list.push_back(fj);
    }
    j["forces"] = list;
  }
  return j;
}

namespace {

// What a body's size fields built, checked before the model sees it: a size so small, or
// positions so far out, that double precision loses the particles' distances gives springs of
// rest length 0 or inf, which the model would report as springs[k].rest_length, a field no
// scene has. Named here by the body's own path instead.
void check_built(const BodyPart& part, const std::string& prefix, const BodySpec& spec) {
  const std::string body =
      (prefix.empty() ? std::string("body") : prefix.substr(0, prefix.size() - 1)) + " (the " +
      std::string(spec.kind()) + " \"" + spec.name + "\")";
  for (int i = 0; i < part.num_particles(); ++i) {
    const Vec3 x = part.position.segment<3>(3 * i);
    if (!x.allFinite()) {
      throw InputError(body, "particle " + std::to_string(i) + " at " + to_text(x.transpose()),
                       "size and position fields (e.g. edge_length, size_u, scale, origin, "
                       "position) that place every particle at finite coordinates");
    }
  }
  const Springs& springs = part.springs;
  for (int k = 0; k < springs.size(); ++k) {
    const Real length = springs.rest_length[k];
    if (!(std::isfinite(length) && length > 0)) {
      throw InputError(
          body,
          "particles " + std::to_string(springs.a[k]) + " and " + std::to_string(springs.b[k]) +
              " " + to_text(length) + " m apart",
          "size and position fields (e.g. edge_length, size_u, scale, origin, position) that "
          "keep neighbouring particles apart in double precision: a larger size, or a "
          "position nearer the origin");
    }
  }
}

}  // namespace

void add_body(Model& model, const BodySpec& spec, const std::string& prefix) {
  spec.validate(prefix);
  require(model.find_body(spec.name) == nullptr, prefix + "name", "\"" + spec.name + "\"",
          "a name no other body has");
  BodyPart part = spec.shape->build(spec.material, prefix);
  check_built(part, prefix, spec);
  const int index = model.add_body(spec.name, std::move(part), spec.radius);
  model.bodies[index].velocity = spec.velocity;
  model.bodies[index].angular_velocity = spec.angular_velocity;
  model.bodies[index].color = spec.color;
  if (spec.thickness) model.bodies[index].thickness = *spec.thickness;
  const Body& body = model.bodies[index];
  // The body's particles are new: no pin holds them yet. Each may be in one of its pins only
  // (two would give it two paths).
  std::vector<int> pinned_by(body.num_particles, -1);
  for (std::size_t k = 0; k < spec.pins.size(); ++k) {
    const std::string at = prefix + "pins[" + std::to_string(k) + "]";
    const PinSpec& pin = spec.pins[k];
    const std::vector<int> chosen = pin.select.resolve(model, body, at + ".");  // sorted, unique
    std::vector<Vec3> anchors;
    anchors.reserve(chosen.size());
    for (int i : chosen) {
      int& by = pinned_by[i - body.first_particle];
      if (by >= 0) {
        Json selection = Json::object();
        pin.select.write(selection);
        throw InputError(at, json_text(selection),
                         "pins that share no particle (particle " +
                             std::to_string(i - body.first_particle) + " of body \"" + body.name +
                             "\" is also in " + prefix + "pins[" + std::to_string(by) +
                             "]: give it one pin, one path)");
      }
      by = static_cast<int>(k);
      anchors.push_back(particle(model.rest_position, i));
    }
    const int path = pin.path.is_fixed() ? model.pins.fixed_path() : model.pins.add_path(pin.path);
    model.pins.add_new(chosen, anchors, path);
  }
  for (std::size_t k = 0; k < spec.forces.size(); ++k) {
    const std::string at = prefix + "forces[" + std::to_string(k) + "].";
    const ExternalForceSpec& e = spec.forces[k];
    ExternalForce force;
    force.kind = e.kind;
    force.particles = e.select.resolve(model, body, at);
    force.vector = e.vector;
    force.drag = e.drag;
    force.gust = e.gust;
    force.gust_frequency = e.gust_frequency;
    force.start = e.start;
    force.end = e.end;
    force.validate(model.num_particles(), at);
    model.external_forces.push_back(std::move(force));
  }
}

}  // namespace jelly
