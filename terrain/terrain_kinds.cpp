#include <jelly/terrain/terrain_kinds.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/detail/mesh_obstacle.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {

const std::vector<TerrainKindInfo>& terrain_kinds() {
  static const std::vector<TerrainKindInfo> kinds{
      {"box",
       "an oriented box obstacle: center, size, rotation_degrees, motion, "
       "angular_velocity_degrees",
       &ObstacleSpec::read_box},
      {"capsule",
       "a capsule obstacle (axis along its own y): center, radius, height (between the caps), "
       "rotation_degrees, motion, angular_velocity_degrees",
       &ObstacleSpec::read_capsule},
      {"cylinder",
       "a capped cylinder obstacle (axis along its own y): center, radius, height, "
       "rotation_degrees, motion, angular_velocity_degrees",
       &ObstacleSpec::read_cylinder},
      {"elevator",
       "a moving platform: center, size_x, size_z, thickness, mass, motion (phases or \"seed\")",
       &ElevatorSpec::read},
      {"mesh",
       "a closed triangle mesh obstacle (OBJ, STL, PLY): file, scale, position, "
       "rotation_degrees, motion, angular_velocity_degrees",
       &MeshObstacleSpec::read},
      {"plane", "a fixed plane: point, normal", &PlaneSpec::read},
      {"slope", "a fixed plane tilted about z: angle_degrees, point", &SlopeSpec::read},
      {"sphere", "a sphere obstacle: center, radius, motion, angular_velocity_degrees",
       &ObstacleSpec::read_sphere},
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

std::unique_ptr<TerrainSpec> read_terrain_spec(const Json& object, const std::string& path,
                                               const std::string& base_directory) {
  JsonFields f(object, path);
  f.set_base_directory(base_directory);
  const std::string kind = f.string("kind");
  std::unique_ptr<TerrainSpec> t = find_terrain_kind(kind, f.path("kind")).read(f);
  if (const Json* c = f.value("contact")) {
    JsonFields g(*c, f.path("contact"));
    t->contact = ContactParams::read(g);
  }
  f.reject_unknown();
  return t;
}

Json terrain_spec_json(const TerrainSpec& spec) {
  Json j;
  j["kind"] = std::string(spec.kind());
  spec.write(j);
  j["contact"] = spec.contact.to_json();
  return j;
}

}  // namespace jelly
