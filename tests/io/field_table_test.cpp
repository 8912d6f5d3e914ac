// Every field of every field table (core/detail/field_table.hpp) through a scene: a valid
// value other than the default is read, written and read back unchanged, and a bad value of
// each constrained field is refused with a message naming the field's JSON path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <filesystem>
#include <map>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>
#include <jelly/io/detail/field_reference.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {
namespace {

// Two bodies and two terrains: a table at bodies[i] or terrains[i] is tried at index 1, one of
// pins or forces at bodies[1].pins[0] or bodies[1].forces[0].
const char* const kFieldScene = R"({
  "bodies": [{"kind": "cube", "name": "a", "n": 3},
             {"kind": "cube", "name": "b", "n": 3, "origin": [5, 0, 0],
              "pins": [{"indices": [0]}], "forces": [{"kind": "constant"}]}],
  "terrains": [{"kind": "plane"}, {"kind": "slope"}],
  "integrator": {"name": "rk4"},
  "duration": 1
})";

std::string asset(const std::string& name) {
  return std::filesystem::canonical(std::string(JELLY_SCENES_DIR) + "/../assets/" + name).string();
}

// A unit cube in 6 tets around its diagonal, written once as a Gmsh file.
std::string tet_cube_file() {
  static const std::string path = [] {
    const std::filesystem::path p =
        std::filesystem::temp_directory_path() / "jelly_field_table_test_cube.msh";
    TetMesh cube;
    for (int c = 0; c < 8; ++c) cube.vertices.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const int turns[6][2] = {{1, 2}, {1, 4}, {2, 1}, {2, 4}, {4, 1}, {4, 2}};
    for (const auto& a : turns) cube.tets.push_back({0, a[0], a[0] + a[1], 7});
    write_msh(p.string(), cube);
    return p.string();
  }();
  return path;
}

// The smallest object of each kind (its required keys), the element a kind's table is tried in.
Json kind_object(const std::string& path, const std::string& kind) {
  Json j = {{"kind", kind}};
  if (path == "bodies[i].forces[j]") {
    if (kind == "wind") j["drag"] = 0.1;
  } else if (path == "bodies[i]") {
    j["name"] = "b";
    if (kind == "voxelized") {
      j["file"] = asset("torus.obj");
      j["spacing"] = 0.2;
    } else if (kind == "tetmesh") {
      j["file"] = tet_cube_file();
    }
  } else if (kind == "sphere") {
    j["radius"] = 0.5;
  } else if (kind == "capsule" || kind == "cylinder") {
    j["radius"] = 0.5;
    j["height"] = 1.0;
  } else if (kind == "mesh") {
    j["file"] = asset("bowl.obj");
  }
  return j;
}

// Whether `written` holds everything `expected` does (objects may hold more keys: defaults).
bool json_contains(const Json& written, const Json& expected) {
  if (expected.is_object()) {
    if (!written.is_object()) return false;
    for (auto it = expected.begin(); it != expected.end(); ++it) {
      if (!written.contains(it.key()) || !json_contains(written[it.key()], it.value()))
        return false;
    }
    return true;
  }
  if (expected.is_array()) {
    if (!written.is_array() || written.size() != expected.size()) return false;
    for (std::size_t i = 0; i < expected.size(); ++i)
      if (!json_contains(written[i], expected[i])) return false;
    return true;
  }
  return written == expected;
}

bool is_integer_field(const FieldDoc& f) { return f.type == "integer"; }

// Values of the field's type other than its default that it allows.
std::vector<Json> field_valid_values(const FieldDoc& f, const Json& element) {
  const Json fallback = Json::parse(f.default_text);
  std::vector<Json> out;
  if (f.type == "object" || f.type == "list") {
    if (!f.example.empty()) out.push_back(Json::parse(f.example));
  } else if (f.type == "file") {
    out.push_back(element.at(f.name));  // the kind's own file, as an absolute path
  } else if (f.name == "kind") {
    // A kind row: its other values are the other kinds' tables.
  } else if (f.type == "choice") {
    for (const std::string& c : f.choices) {
      if (Json(c) != fallback) out.emplace_back(c);
    }
  } else if (f.type == "boolean") {
    out.emplace_back(!fallback.get<bool>());
  } else if (f.type == "string") {
    out.emplace_back("a_round_trip_value");
  } else if (f.type == "vec3") {
    out.push_back(f.per_component ? Json::array({0.25, 0.5, 0.75})
                                  : Json::array({0.25, -2.0, 3.5}));
  } else {
    const FieldRange& r = f.range;
    const double d = fallback.is_number() ? fallback.get<double>() : std::nan("");
    std::vector<double> candidates{
        r.lo, r.hi, r.lo + 1, r.hi - 1, 2 * d, d + 1, d / 2, (r.lo + r.hi) / 2, 0.5, 1, 3};
    // A limit on the scene's size: more than the default, not the least it allows.
    if (f.name == "max_particles") candidates.insert(candidates.begin(), 2 * d);
    // A required size the kind's object gives (a voxelized body's spacing): half of it.
    if (element.contains(f.name) && element[f.name].is_number())
      candidates.insert(candidates.begin(), element[f.name].get<double>() / 2);
    for (double c : candidates) {
      if (!std::isfinite(c) || !r.contains(c) || c == d) continue;
      if (is_integer_field(f)) {
        if (c != std::floor(c)) continue;
        out.emplace_back(static_cast<long long>(c));
      } else {
        out.emplace_back(c);
      }
      break;
    }
  }
  return out;
}

// Values of the field's JSON type that its constraint refuses.
std::vector<Json> field_bad_values(const FieldDoc& f) {
  std::vector<Json> out;
  if (f.type == "choice") {
    out.emplace_back("no_such_name");
  } else if (f.type == "vec3" && f.per_component) {
    const FieldRange& r = f.range;
    for (double c : {r.lo, r.lo - 1, r.hi, r.hi + 1}) {
      if (std::isfinite(c) && !r.contains(c)) {
        out.push_back(Json::array({c, c, c}));
        break;
      }
    }
  } else if (f.type == "vec3") {
    if (f.range.lo > 0) out.push_back(Json::array({0.0, 0.0, 0.0}));  // a length > lo
    if (std::isfinite(f.range.hi)) out.push_back(Json::array({2 * f.range.hi + 1, 0.0, 0.0}));
  } else if (f.type == "file") {
    out.emplace_back("");
  } else if (f.type == "integer" || f.type == "number") {
    const FieldRange& r = f.range;
    for (double c : {r.lo, r.lo - 1, r.hi, r.hi + 1, r.lo - 0.5, r.hi + 0.5}) {
      if (!std::isfinite(c) || r.contains(c) || (is_integer_field(f) && c != std::floor(c)))
        continue;
      if (is_integer_field(f)) {
        out.emplace_back(static_cast<long long>(c));
      } else {
        out.emplace_back(c);
      }
    }
  }
  return out;
}

// A table's path in the test scene: "terrains[i].contact" -> "terrains[1].contact",
// "bodies[i].pins[j]" -> "bodies[1].pins[0]".
std::string table_scene_path(const std::string& path) {
  std::string out = path;
  for (std::size_t at = out.find("[i]"); at != std::string::npos; at = out.find("[i]"))
    out.replace(at, 3, "[1]");
  for (std::size_t at = out.find("[j]"); at != std::string::npos; at = out.find("[j]"))
    out.replace(at, 3, "[0]");
  return out;
}

// A field's JSON path in the test scene: "bodies[1].velocity", "duration".
std::string field_path(const std::string& table_path, const FieldDoc& f) {
  return table_path.empty() ? f.name : table_scene_path(table_path) + "." + f.name;
}

std::string field_override(const std::string& path, const FieldDoc& f, const Json& value) {
  return field_path(path, f) + "=" + value.dump();
}

// The object at a scene path ("terrains[0].contact") of a written scene.
const Json& json_at(const Json& scene, const std::string& path) {
  if (path.empty()) return scene;
  const Json* j = &scene;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t dot = std::min(path.find('.', start), path.size());
    std::string key = path.substr(start, dot - start);
    const std::size_t bracket = key.find('[');
    if (bracket == std::string::npos) {
      j = &j->at(key);
    } else {
      j = &j->at(key.substr(0, bracket)).at(std::stoul(key.substr(bracket + 1)));
    }
    start = dot + 1;
  }
  return *j;
}

std::vector<std::string> with_override(std::vector<std::string> overrides,
                                       const std::string& more) {
  overrides.push_back(more);
  return overrides;
}

bool is_integrator_options(const FieldTableDoc& t) { return t.path == "integrator.options"; }

// The integrators a table's options are tried with: its users, or the scene's own (rk4).
std::vector<std::string> table_integrators(const FieldTableDoc& t) {
  return is_integrator_options(t) ? t.used_by : std::vector<std::string>{"rk4"};
}

// The overrides that make the scene use the table: its integrator, or its kind of terrain or
// body at index 0 (replacing the scene's slope or cube).
std::vector<std::string> table_overrides(const FieldTableDoc& t, const std::string& integrator) {
  std::vector<std::string> out{"integrator.name=\"" + integrator + "\""};
  if (!is_integrator_options(t) && !t.used_by.empty())
    out.push_back(table_scene_path(t.path) + "=" + kind_object(t.path, t.used_by.front()).dump());
  return out;
}

// The object of the test scene a kind's table is tried in (empty for the other tables).
Json table_element(const FieldTableDoc& t) {
  if (t.used_by.empty() || is_integrator_options(t)) return Json::object();
  return kind_object(t.path, t.used_by.front());
}

TEST(FieldTables, TheReferenceListsEveryIntegratorOptionTable) {
  const std::vector<FieldTableDoc> tables = scene_field_tables();
  ASSERT_GE(tables.size(), 5u);
  for (const FieldTableDoc& t : tables) {
    EXPECT_FALSE(t.fields.empty()) << t.name;
    const bool kind_table =
        t.path == "terrains[i]" || t.path == "bodies[i]" || t.path == "bodies[i].forces[j]";
    if (!t.used_by.empty()) {
      EXPECT_TRUE(kind_table || is_integrator_options(t)) << t.name;
    }
    if (is_integrator_options(t)) {
      EXPECT_FALSE(t.used_by.empty()) << t.name;
    }
    for (const FieldDoc& f : t.fields) {
      EXPECT_FALSE(f.help.empty()) << t.name << "." << f.name;
      EXPECT_FALSE(f.allowed.empty()) << t.name << "." << f.name;
      EXPECT_NO_THROW(Json::parse(f.default_text)) << t.name << "." << f.name;
    }
  }
  const std::string markdown = field_tables_markdown(tables);
  EXPECT_THAT(markdown, ::testing::HasSubstr("| `newton_iterations` | integer | `1` |"));
  const Json json = Json::parse(field_tables_json(tables));
  EXPECT_EQ(json.size(), tables.size());
}

TEST(FieldTables, EveryFieldRoundTripsThroughAScene) {
  int checked = 0;
  for (const FieldTableDoc& t : scene_field_tables()) {
    std::vector<std::string> overrides = table_overrides(t, table_integrators(t).back());
    const Json element = table_element(t);
    for (const FieldDoc& f : t.fields) {
      // The integrator's name: another method (any other string is refused).
      const std::vector<Json> values = t.path == "integrator" && f.name == "name"
                                           ? std::vector<Json>{Json("midpoint")}
                                           : field_valid_values(f, element);
      // Kind rows (their values are the kinds' tables) and object rows without an example (the
      // object's own table: body_contact, divergence, ...) have no value of their own to try.
      const bool own_table = (f.type == "object" && f.example.empty()) || f.name == "kind";
      if (own_table) continue;
      ASSERT_FALSE(values.empty()) << t.name << "." << f.name << ": no valid value to try";
      for (const Json& value : values) {
        SCOPED_TRACE(t.name + "." + f.name + " = " + value.dump());
        const Scene scene =
            parse_scene(kFieldScene, with_override(overrides, field_override(t.path, f, value)));
        const std::string written = scene_to_json(scene);
        const Json written_json = Json::parse(written);
        const Json& got = json_at(written_json, table_scene_path(t.path))[f.name];
        if (f.type == "object" || f.type == "list") {
          EXPECT_TRUE(json_contains(got, value)) << got.dump();
        } else {
          EXPECT_EQ(got, value);
        }
        const Scene again = parse_scene(written);
        EXPECT_EQ(scene_to_json(again), written);
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 150);
}

TEST(FieldTables, ABadValueOfEachConstrainedFieldIsRefusedNamingTheField) {
  int checked = 0;
  for (const FieldTableDoc& t : scene_field_tables()) {
    for (const std::string& integrator : table_integrators(t)) {
      std::vector<std::string> overrides = table_overrides(t, integrator);
      for (const FieldDoc& f : t.fields) {
        const std::vector<Json> values = field_bad_values(f);
        EXPECT_EQ(values.empty(), !f.constrained) << t.name << "." << f.name;
        for (const Json& value : values) {
          SCOPED_TRACE(integrator + ": " + f.name + " = " + value.dump());
          try {
            parse_scene(kFieldScene, with_override(overrides, field_override(t.path, f, value)));
            ADD_FAILURE() << "accepted";
          } catch (const InputError& e) {
            EXPECT_THAT(e.what(), ::testing::StartsWith(field_path(t.path, f) + " = "));
            EXPECT_THAT(e.what(), ::testing::HasSubstr(f.allowed));
          }
          ++checked;
        }
      }
    }
  }
  EXPECT_GE(checked, 30);
}

}  // namespace
}  // namespace jelly
