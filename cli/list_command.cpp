#include <cstdio>
#include <string>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/contact_params.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

namespace {

const char* terrain_description(TerrainKind kind) {
  switch (kind) {
    case TerrainKind::kPlane:
      return "a fixed plane: point, normal";
    case TerrainKind::kSlope:
      return "a fixed plane tilted about z: angle_degrees, point";
    case TerrainKind::kElevator:
      return "a moving platform: center, size_x, size_z, thickness, mass, motion";
  }
  return "";
}

const char* contact_description(ContactModel model) {
  switch (model) {
    case ContactModel::kCoulomb:
      return "projection, restitution above a resting speed, Coulomb friction (default)";
    case ContactModel::kSeed:
      return "the seed report's rules: reflection within epsilon, friction -mu N v_t";
  }
  return "";
}

void line(const std::string& kind, std::string_view name, std::string_view description) {
  std::printf("%-10s %-18s %.*s\n", kind.c_str(), std::string(name).c_str(),
              static_cast<int>(description.size()), description.data());
}

}  // namespace

int list_command() {
  for (const IntegratorInfo& info : integrator_infos())
    line("integrator", info.name, info.description);
  for (TerrainKind kind : terrain_kinds()) {
    line("terrain", terrain_kind_name(kind), terrain_description(kind));
  }
  for (ContactModel model : {ContactModel::kCoulomb, ContactModel::kSeed}) {
    line("contact", contact_model_name(model), contact_description(model));
  }
  return kExitOk;
}

}  // namespace jelly::cli
