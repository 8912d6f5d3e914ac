#pragma once
// Every terrain kind a scene can name, from one table: adding a kind is its own files (spec,
// terrain) and one line there.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/terrain/terrain_spec.hpp>

namespace jelly {

struct TerrainKindInfo {
  std::string_view name;
  std::string_view description;  // one line, with the kind's keys
  // Reads the kind's keys from `fields` (which names the JSON path), validates them and returns
  // the spec; leaves "kind" and "contact" to the caller.
  std::unique_ptr<TerrainSpec> (*read)(JsonFields& fields);
};

// Sorted by name.
const std::vector<TerrainKindInfo>& terrain_kinds();
// Throws InputError naming `field` and listing the known kinds for an unknown name.
const TerrainKindInfo& find_terrain_kind(std::string_view name, const std::string& field);

// A whole terrain object of a scene ({"kind": ..., the kind's keys, "contact": {...}}) at the JSON
// path `path`: read, validated, unknown keys refused (InputError naming the path). File names
// (a mesh obstacle's) are relative to `base_directory` ("" = the current directory).
std::unique_ptr<TerrainSpec> read_terrain_spec(const Json& object, const std::string& path,
                                               const std::string& base_directory = "");
// The same object written out with every key.
Json terrain_spec_json(const TerrainSpec& spec);

}  // namespace jelly
