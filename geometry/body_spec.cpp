#include <jelly/geometry/body_spec.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

namespace jelly {

bool Box3::contains(const Vec3& p) const {
  return (min_.array() <= p.array()).all() && (p.array() <= max_.array()).all();
}

namespace {

constexpr const char* kSpringKeys[kSpringTypeCount] = {"structural", "shear", "bending"};

}  // namespace

void read_springs(JsonFields& f, std::array<SpringCoefficients, kSpringTypeCount>& springs) {
  for (int t = 0; t < kSpringTypeCount; ++t) {
    if (const Json* one = f.value(kSpringKeys[t])) {
      JsonFields g(*one, f.path(kSpringKeys[t]));
      read_fields(spring_fields(), g, springs[t], g.prefix(), /*reject_unknown=*/true);
    }
  }
  f.reject_unknown();
}

Json springs_json(const std::array<SpringCoefficients, kSpringTypeCount>& springs) {
  Json j;
  for (int t = 0; t < kSpringTypeCount; ++t) {
    j[kSpringKeys[t]] = Json::object();
    write_fields(spring_fields(), springs[t], j[kSpringKeys[t]]);
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

// Through the pin table's selection rows (the same for forces).
ParticleSelection ParticleSelection::read(JsonFields& f) {
  PinSpec pin;
  for (const Field<PinSpec>& row : pin_fields().fields) {
    if (row.name != "path") row.read(f, pin, row.name);
  }
  return pin.select;
}

void ParticleSelection::write(Json& j) const {
  PinSpec pin;
  pin.select = *this;
  write_fields(pin_fields(), pin, j);  // the fixed path is not written
}

namespace {

// A selection's rows (indices, region, group) of a struct whose member `Select` holds it, each
// written only when given.
template <typename S, ParticleSelection S::*Select>
std::vector<Field<S>> selection_rows() {
  Field<S> indices = object_field<S>(
      "indices", FieldType::kList, "a list of at least one particle index",
      "Particles by index in the body (with region and group: the union; none: the whole body)",
      "[0, 2]",
      [](JsonFields& f, S& s, std::string_view key) {
        if (const Json* idx = f.value(key)) {
          if (!idx->is_array() || idx->empty()) {
            throw InputError(f.path(key), json_text(*idx),
                             "a list of at least one particle index (leave \"indices\", "
                             "\"region\" and \"group\" out to choose the whole body)");
          }
          for (std::size_t i = 0; i < idx->size(); ++i) {
            (s.*Select).indices.push_back(json_integer((*idx)[i], json_element(f.path(key), i)));
          }
        }
      },
      [](const S& s, Json& j, std::string_view key) { j[std::string(key)] = (s.*Select).indices; });
  indices.is_default = [](const S& s) { return (s.*Select).indices.empty(); };
  indices.omit_default = true;
  Field<S> region = object_field<S>(
      "region", FieldType::kObject, "{\"min\": [x, y, z], \"max\": [x, y, z]}, min <= max",
      "Particles inside this box at rest (world coordinates)",
      R"({"min": [-100.0, -100.0, -100.0], "max": [100.0, 100.0, 100.0]})",
      [](JsonFields& f, S& s, std::string_view key) {
        if (const Json* r = f.value(key)) {
          JsonFields g(*r, f.path(key));
          const Vec3 lo = json_vec3(g.value("min") ? *g.value("min") : Json(), g.path("min"));
          const Vec3 hi = json_vec3(g.value("max") ? *g.value("max") : Json(), g.path("max"));
          g.reject_unknown();
          require((lo.array() <= hi.array()).all(), g.path("max"), hi.transpose(),
                  "a corner >= min in every coordinate");
          (s.*Select).has_region = true;
          (s.*Select).region = Box3(lo, hi);
        }
      },
      [](const S& s, Json& j, std::string_view key) {
        const Box3& r = (s.*Select).region;
        j[std::string(key)] = {{"min", json_of(r.min())}, {"max", json_of(r.max())}};
      });
  region.is_default = [](const S& s) { return !(s.*Select).has_region; };
  region.omit_default = true;
  return {indices, region,
          omit_default(string_field<Select, &ParticleSelection::group>(
              "group", "a group of the body (a mesh's vertex group, a cloth's corner or edge)",
              "Particles of a named group of the body"))};
}

}  // namespace

const FieldTable<PinSpec>& pin_fields() {
  static const FieldTable<PinSpec> table = [] {
    std::vector<Field<PinSpec>> rows = selection_rows<PinSpec, &PinSpec::select>();
    Field<PinSpec> path = json_value_field<&PinSpec::path>(
        "path",
        "\"fixed\" or a path {\"kind\": phases, keyframes, oscillation, circle or linear, ...}",
        "Where the pinned particles go from their rest positions (docs/scenes.md, pins)",
        R"({"kind": "oscillation", "amplitude": [0.0, 0.1, 0.0], "frequency": 1.0, "phase": 0.0})");
    path.is_default = [](const PinSpec& p) { return p.path.is_fixed(); };
    path.omit_default = true;
    rows.push_back(path);
    return FieldTable<PinSpec>{"PinSpec", "bodies[i].pins[j]",
                               "Particles of the body held on a path", std::move(rows)};
  }();
  return table;
}

namespace {

using ForceSpec = ExternalForceSpec;

std::vector<std::string> external_force_kind_names() {
  std::vector<std::string> out;
  for (const auto& k : external_force_kinds()) out.emplace_back(k.name);
  return out;
}

// One force kind's rows: kind, the selection, its vector (force or the wind's velocity and
// drag), then the gust and the time window.
FieldTable<ForceSpec> force_table(ExternalForceKind kind, std::string_view name,
                                  std::string_view title) {
  Field<ForceSpec> kind_row = object_field<ForceSpec>(
      "kind", FieldType::kChoice, "one of " + quoted_names(external_force_kinds()),
      "The force kind; its keys are its table's", "",
      [](JsonFields& f, ForceSpec& e, std::string_view key) {
        e.kind = external_force_kind_from_name(f.string(key), f.path(key));
      },
      [](const ForceSpec& e, Json& j, std::string_view key) {
        j[std::string(key)] = std::string(external_force_kind_name(e.kind));
      });
  kind_row.required = true;
  kind_row.constrained = true;
  kind_row.choices = external_force_kind_names;
  std::vector<Field<ForceSpec>> rows{kind_row};
  for (Field<ForceSpec>& f : selection_rows<ForceSpec, &ForceSpec::select>()) rows.push_back(f);
  if (kind == ExternalForceKind::kWind) {
    rows.push_back(vec3_field<&ForceSpec::vector>("velocity", "m/s", range_finite(),
                                                  "finite components", "Velocity of the air (w)"));
    rows.push_back(required(number_field<&ForceSpec::drag>("drag", "N s/m", range_at_least(0),
                                                           "a finite drag >= 0 N s/m",
                                                           "Per particle: f = drag (w(t) - v)")));
  } else {
    rows.push_back(vec3_field<&ForceSpec::vector>(
        "force", "N", range_finite(), "finite components",
        kind == ExternalForceKind::kConstant
            ? "The total, spread over the particles in proportion to their masses"
            : "On each selected particle"));
  }
  rows.push_back(number_field<&ForceSpec::gust>("gust", "", range_finite(),
                                                "a finite relative amplitude",
                                                "w(t) = w (1 + gust sin(2 pi gust_frequency t))"));
  rows.push_back(number_field<&ForceSpec::gust_frequency>(
      "gust_frequency", "Hz", range_at_least(0), "a finite frequency >= 0 Hz", "Of the gust"));
  rows.push_back(number_field<&ForceSpec::start>("start", "s", range_at_least(0),
                                                 "a finite time >= 0 s", "When it starts"));
  rows.push_back(number_or_inf_field<&ForceSpec::end>("end", "s", range_or_infinite(FieldRange{}),
                                                      "a time after start (or inf)",
                                                      "When it stops (\"inf\": never)"));
  return FieldTable<ForceSpec>{name, "bodies[i].forces[j]", title, std::move(rows),
                               [](const ForceSpec& e, const std::string& prefix) {
                                 require(!std::isnan(e.end) && e.end > e.start, prefix + "end",
                                         e.end, "a time after start (or inf)");
                               }};
}

}  // namespace

const FieldTable<ExternalForceSpec>& external_force_fields(ExternalForceKind kind) {
  static const FieldTable<ForceSpec> constant =
      force_table(ExternalForceKind::kConstant, "ExternalForceSpec (constant)",
                  "A force spread over the chosen particles by mass");
  static const FieldTable<ForceSpec> point = force_table(
      ExternalForceKind::kPoint, "ExternalForceSpec (point)", "A force on each chosen particle");
  static const FieldTable<ForceSpec> wind = force_table(
      ExternalForceKind::kWind, "ExternalForceSpec (wind)", "Drag towards the air's velocity");
  switch (kind) {
    case ExternalForceKind::kConstant:
      return constant;
    case ExternalForceKind::kPoint:
      return point;
    case ExternalForceKind::kWind:
      return wind;
  }
  return constant;
}

namespace {

void read_body_pins(JsonFields& f, BodySpec& b, std::string_view key) {
  const Json* pins = f.value(key);
  if (pins == nullptr) return;
  if (!pins->is_array()) throw InputError(f.path("pins"), json_text(*pins), "a list of pins");
  for (std::size_t i = 0; i < pins->size(); ++i) {
    JsonFields g((*pins)[i], json_element(f.path("pins"), i));
    PinSpec pin;
    read_fields(pin_fields(), g, pin, g.prefix(), /*reject_unknown=*/true);
    b.pins.push_back(std::move(pin));
  }
}

void write_body_pins(const BodySpec& b, Json& j, std::string_view key) {
  Json list = Json::array();
  for (const PinSpec& p : b.pins) {
    Json pj = Json::object();
    write_fields(pin_fields(), p, pj);
    list.push_back(pj);
  }
  j[std::string(key)] = list;
}

void read_body_forces(JsonFields& f, BodySpec& b, std::string_view key) {
  const Json* forces = f.value(key);
  if (forces == nullptr) return;
  if (!forces->is_array()) {
    throw InputError(f.path("forces"), json_text(*forces), "a list of external forces");
  }
  for (std::size_t i = 0; i < forces->size(); ++i) {
    JsonFields g((*forces)[i], json_element(f.path("forces"), i));
    const ExternalForceKind kind = external_force_kind_from_name(g.string("kind"), g.path("kind"));
    ExternalForceSpec e;
    e.kind = kind;
    read_fields(external_force_fields(kind), g, e, g.prefix(), /*reject_unknown=*/true);
    b.forces.push_back(std::move(e));
  }
}

void write_body_forces(const BodySpec& b, Json& j, std::string_view key) {
  Json list = Json::array();
  for (const ExternalForceSpec& e : b.forces) {
    Json fj = Json::object();
    write_fields(external_force_fields(e.kind), e, fj);
    list.push_back(fj);
  }
  j[std::string(key)] = list;
}

std::vector<std::string> body_kind_names() {
  std::vector<std::string> out;
  for (const BodyKindInfo& k : body_kinds()) out.emplace_back(k.name);
  return out;
}

std::string body_kinds_allowed() {
  std::string out;
  for (const std::string& k : body_kind_names()) out += (out.empty() ? "\"" : ", \"") + k + "\"";
  return "one of " + out;
}

// The kind row: "kind" names the shape, whose own keys (its table) sit beside it.
Field<BodySpec> body_kind_field() {
  Field<BodySpec> row = object_field<BodySpec>(
      "kind", FieldType::kChoice, body_kinds_allowed(),
      "The body kind; its own keys are in its table (bodies[i] of that kind)", "",
      [](JsonFields& f, BodySpec& b, std::string_view key) {
        const std::string kind = f.string(key);
        b.shape = find_body_kind(kind, f.path(key)).read(f);
      },
      [](const BodySpec& b, Json& j, std::string_view key) {
        j[std::string(key)] = std::string(b.kind());
        if (b.shape) b.shape->write(j);  // none: a default BodySpec (the reference's)
      });
  row.required = true;
  row.constrained = true;
  row.choices = body_kind_names;
  return row;
}

// A list row written only when it holds something.
Field<BodySpec> omitted_when_empty(Field<BodySpec> f, bool (*empty)(const BodySpec&)) {
  f.is_default = empty;
  f.omit_default = true;
  return f;
}

}  // namespace

const FieldTable<BodySpec>& body_fields() {
  using B = BodySpec;
  static const FieldTable<B> table{
      "BodySpec",
      "bodies[i]",
      "The keys every body has, whatever its kind",
      {
          string_field<&B::name>("name", "a non-empty name without '/' or '.', unique in the scene",
                                 "The body's name (its group in a recording)"),
          body_kind_field(),
          object_field<B>(
              "springs", FieldType::kObject,
              "an object with structural, shear and bending, each SpringCoefficients",
              "Coefficients per spring type (each key optional)",
              R"({"structural": {"ks": 2000.0, "kd": 10.0}, "shear": {"ks": 1400.0, "kd": 50.0}, )"
              R"("bending": {"ks": 1400.0, "kd": 50.0}})",
              [](JsonFields& f, B& b, std::string_view key) {
                if (const Json* sp = f.value(key)) {
                  JsonFields g(*sp, f.path(key));
                  read_springs(g, b.material.springs);
                }
              },
              [](const B& b, Json& j, std::string_view key) {
                j[std::string(key)] = springs_json(b.material.springs);
              }),
          particle_mass_field<&B::material, &Material::particle_mass>(),
          density_field<&B::material, &Material::density>(),
          number_field<&B::radius>(
              "radius", "m", range_at_least(0),
              "a finite radius >= 0 m (0 = half the lattice spacing)",
              "Contact radius of its particles (0 = half the lattice spacing)"),
          optional_number_field<&B::thickness>(
              "thickness", "m", range_at_least(0),
              "a finite distance >= 0 m (the default: the contact radius for a cloth, 0 for a body "
              "with volume)",
              "Distance its particles keep from terrains and obstacles"),
          omit_default(vec3_field<&B::velocity>("velocity", "m/s", range_finite(),
                                                "finite components (m/s)",
                                                "Initial velocity of every particle")),
          omit_default(vec3_field<&B::angular_velocity>(
              "angular_velocity", "rad/s", range_finite(), "finite components (rad/s)",
              "Initial angular velocity about the centre of mass")),
          optional_vec3_field<&B::color>("color", "", range_closed(0, 1),
                                         "[r, g, b], each in [0, 1]",
                                         "sRGB colour in the viewer (none: its palette)"),
          omitted_when_empty(
              object_field<B>("pins", FieldType::kList,
                              "a list of pins: indices, region {min, max} and/or group; path",
                              "Particles held on a path (fixed by default)",
                              R"([{"indices": [0], "path": {"kind": "oscillation", )"
                              R"("amplitude": [0.0, 0.1, 0.0], "frequency": 1.0, "phase": 0.0}}])",
                              read_body_pins, write_body_pins),
              [](const B& b) { return b.pins.empty(); }),
          omitted_when_empty(
              object_field<B>("forces", FieldType::kList,
                              "a list of forces: kind (constant: force; wind: velocity, drag), "
                              "indices/region/group, gust, gust_frequency, start, end",
                              "External forces on chosen particles",
                              R"([{"kind": "constant", "force": [0.0, 1.0, 0.0], "gust": 0.0, )"
                              R"("gust_frequency": 0.0, "start": 0.0, "end": "inf"}])",
                              read_body_forces, write_body_forces),
              [](const B& b) { return b.forces.empty(); }),
      },
      // Rules beyond one field: the name, the kind's own keys, the springs.
      [](const B& b, const std::string& prefix) {
        require(!b.name.empty(), prefix + "name", "\"\"", "a non-empty name");
        require(b.name.find_first_of("/.") == std::string::npos, prefix + "name",
                "\"" + b.name + "\"", "a name without '/' or '.' (it names an HDF5 group)");
        require(static_cast<bool>(b.shape), prefix + "kind", "none", "a body kind");
        b.shape->validate(prefix);
        b.material.validate(prefix);
      },
  };
  return table;
}

void BodySpec::validate(const std::string& prefix) const {
  validate_fields(body_fields(), *this, prefix);
}

BodySpec BodySpec::read(JsonFields& f) {
  BodySpec b;
  read_fields(body_fields(), f, b, f.prefix(), /*reject_unknown=*/true);
  return b;
}

Json BodySpec::to_json() const {
  Json j;
  write_fields(body_fields(), *this, j);
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
