#include <cstdio>
#include <string>

#include <jelly/core/components.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/tetrahedralize.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

namespace {

void line(std::string_view kind, std::string_view name, std::string_view description) {
  std::printf("%-10.*s %-18.*s %.*s\n", static_cast<int>(kind.size()), kind.data(),
              static_cast<int>(name.size()), name.data(), static_cast<int>(description.size()),
              description.data());
}

}  // namespace

// The components this program has, then every kind a scene can name, read from the registries
// (a component's kinds are there only when the component is).
int list_command() {
  for (const ComponentInfo& c : components()) line("component", c.name, c.description);
  for (const IntegratorInfo& info : integrator_infos())
    line("integrator", info.name, info.description);
  for (const BodyKindInfo& k : body_kinds()) line("body", k.name, k.description);
  for (const TerrainKindInfo& k : terrain_kinds()) line("terrain", k.name, k.description);
  for (const EnumName<ContactModel>& m : contact_models()) line("contact", m.name, m.description);
  for (const EnumName<ExternalForceKind>& k : external_force_kinds()) {
    line("force", k.name, k.description);
  }
  const std::string no_gmsh = tetrahedralize_unavailable_reason();
  line("mesher", "gmsh",
       no_gmsh.empty() ? "fills closed surfaces with tetrahedra (jelly mesh); loaded on first use"
                       : "not available: " + no_gmsh);
  return kExitOk;
}

}  // namespace jelly::cli
