// Every field of every field table (core/detail/field_table.hpp) through a scene: a valid
// value other than the default is read, written and read back unchanged, and a bad value of
// each constrained field is refused with a message naming the field's JSON path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/field_reference.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {
namespace {

const char* const kFieldScene = R"({
  "bodies": [{"kind": "cube", "n": 3}],
  "terrains": [{"kind": "slope"}],
  "integrator": {"name": "rk4"},
  "duration": 1
})";

bool is_integer_field(const FieldDoc& f) { return f.type == "integer"; }

// Values of the field's type other than its default that it allows.
std::vector<Json> field_valid_values(const FieldDoc& f) {
  const Json fallback = Json::parse(f.default_text);
  std::vector<Json> out;
  if (f.type == "choice") {
    for (const std::string& c : f.choices) {
      if (Json(c) != fallback) out.emplace_back(c);
    }
  } else if (f.type == "boolean") {
    out.emplace_back(!fallback.get<bool>());
  } else if (f.type == "string") {
    out.emplace_back("a_round_trip_value");
  } else if (f.type == "vec3") {
    out.push_back(Json::array({0.25, -2.0, 3.5}));
  } else {
    const FieldRange& r = f.range;
    const double d = fallback.get<double>();
    std::vector<double> candidates{
        r.lo, r.hi, r.lo + 1, r.hi - 1, 2 * d, d + 1, d / 2, (r.lo + r.hi) / 2, 0.5, 1, 3};
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
  } else if (f.type == "vec3") {
    if (f.range.lo > 0) out.push_back(Json::array({0.0, 0.0, 0.0}));  // a length > lo
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

// A table's path in the test scene: "terrains[i].contact" -> "terrains[0].contact".
std::string table_scene_path(const std::string& path) {
  std::string out = path;
  for (std::size_t at = out.find("[i]"); at != std::string::npos; at = out.find("[i]"))
    out.replace(at, 3, "[0]");
  return out;
}

std::string field_override(const std::string& path, const FieldDoc& f, const Json& value) {
  return table_scene_path(path) + "." + f.name + "=" + value.dump();
}

// The object at a scene path ("terrains[0].contact") of a written scene.
const Json& json_at(const Json& scene, const std::string& path) {
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
    out.push_back(table_scene_path(t.path) + ".kind=\"" + t.used_by.front() + "\"");
  return out;
}

TEST(FieldTables, TheReferenceListsEveryIntegratorOptionTable) {
  const std::vector<FieldTableDoc> tables = scene_field_tables();
  ASSERT_GE(tables.size(), 5u);
  for (const FieldTableDoc& t : tables) {
    EXPECT_FALSE(t.fields.empty()) << t.name;
    const bool kind_table = t.path == "terrains[i]" || t.path == "bodies[i]";
    EXPECT_EQ(t.used_by.empty(), !kind_table && !is_integrator_options(t)) << t.name;
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
    for (const FieldDoc& f : t.fields) {
      const std::vector<Json> values = field_valid_values(f);
      ASSERT_FALSE(values.empty()) << t.name << "." << f.name << ": no valid value to try";
      for (const Json& value : values) {
        SCOPED_TRACE(t.name + "." + f.name + " = " + value.dump());
        const Scene scene =
            parse_scene(kFieldScene, with_override(overrides, field_override(t.path, f, value)));
        const std::string written = scene_to_json(scene);
        EXPECT_EQ(json_at(Json::parse(written), table_scene_path(t.path))[f.name], value);
        const Scene again = parse_scene(written);
        EXPECT_EQ(scene_to_json(again), written);
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 30);
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
            EXPECT_THAT(e.what(),
                        ::testing::StartsWith(table_scene_path(t.path) + "." + f.name + " = "));
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
