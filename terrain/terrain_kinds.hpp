#pragma once
// Every terrain kind a scene can name, from one table: adding a kind is its own files (spec,
// terrain) and one line there.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/terrain/terrain.hpp>

// What a scene says of one terrain: the kind's parameters (a subclass per kind, beside its
// terrain) and the contact model that answers particles touching it. A spec validates itself,
// makes its terrain and writes itself back as JSON; the registry (terrain_kinds.hpp) reads it.
namespace jelly {

// A terrain as a scene gives it: its kind's parameters and its contact; makes the Terrain.
class TerrainSpec {
 public:
  ContactParams contact;  // the contact model that answers particles touching the terrain

  virtual ~TerrainSpec() = default;
  // The terrain kind's name in scenes ("plane", ...).
  virtual std::string_view kind() const = 0;
  // A copy of the same class.
  virtual std::unique_ptr<TerrainSpec> clone() const = 0;
  // Throws InputError naming `prefix`field (a scene passes its JSON path, "terrains[0]."); the
  // contact is validated by the caller.
  virtual void validate(const std::string& prefix) const = 0;
  // The terrain, answering with `contact`.
  virtual std::unique_ptr<Terrain> make() const = 0;
  // Writes the kind's own keys (not "kind" and "contact") into `object`.
  virtual void write(Json& object) const = 0;
};

// Implements clone() for a spec class.
template <typename Derived>
class TerrainSpecOf : public TerrainSpec {
 public:
  // A copy of the same class.
  std::unique_ptr<TerrainSpec> clone() const override {
    return std::make_unique<Derived>(static_cast<const Derived&>(*this));
  }
};

}  // namespace jelly

namespace jelly {

// One terrain kind of the registry: its name, description and how its keys are read.
struct TerrainKindInfo {
  std::string_view name;         // the kind's name in scenes
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
