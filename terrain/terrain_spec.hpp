#pragma once
// What a scene says of one terrain: the kind's parameters (a subclass per kind, beside its
// terrain) and the contact model that answers particles touching it. A spec validates itself,
// makes its terrain and writes itself back as JSON; the registry (terrain_kinds.hpp) reads it.
#include <memory>
#include <string>
#include <string_view>

#include <jelly/core/json_fwd.hpp>
#include <jelly/terrain/contact_params.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

class TerrainSpec {
 public:
  ContactParams contact;  // the contact model that answers particles touching the terrain

  virtual ~TerrainSpec() = default;
  virtual std::string_view kind() const = 0;
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
  std::unique_ptr<TerrainSpec> clone() const override {
    return std::make_unique<Derived>(static_cast<const Derived&>(*this));
  }
};

}  // namespace jelly
