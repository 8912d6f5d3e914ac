#include <jelly/terrain/terrain_kinds.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/terrain/elevator.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {

const std::vector<TerrainKindInfo>& terrain_kinds() {
  static const std::vector<TerrainKindInfo> kinds{
      {"elevator",
       "a moving platform: center, size_x, size_z, thickness, mass, motion (phases or \"seed\")",
       &ElevatorSpec::read},
      {"plane", "a fixed plane: point, normal", &PlaneSpec::read},
      {"slope", "a fixed plane tilted about z: angle_degrees, point", &SlopeSpec::read},
  };
  return kinds;
}

const TerrainKindInfo& find_terrain_kind(std::string_view name, const std::string& field) {
  std::string known;
  for (const TerrainKindInfo& k : terrain_kinds()) {
    if (k.name == name) return k;
    known += (known.empty() ? "\"" : ", \"") + std::string(k.name) + "\"";
  }
  throw InputError(field, "\"" + std::string(name) + "\"", "one of " + known);
}

}  // namespace jelly
