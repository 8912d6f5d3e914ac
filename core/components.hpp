#pragma once
// The components this program has (docs/CONTRIBUTING.md, "Components"): the core library and
// each optional one linked in (io, meshes, arkode, fit). A component registers itself and its
// kinds (integrators, mesh readers) when a program that links it starts; `jelly list` shows them.
#include <string>
#include <string_view>
#include <vector>

namespace jelly {

// A component of this program: its name and what it brings.
struct ComponentInfo {
  std::string_view name;         // "core", "io", "meshes", "arkode", "fit", "viewer"
  std::string_view description;  // what it brings, one line
};

// The registered components, core first, then in registration order; each name once.
std::vector<ComponentInfo> components();

// True when the component `name` is registered in this program.
bool has_component(std::string_view name);

// Adds a component (a second call with the same name does nothing). Called by the components'
// registration functions before main; not safe while another thread reads the registries.
void register_component(const ComponentInfo& info);

// Each optional component's registration: it registers the component and its kinds, once. The
// CMake targets jelly::io, jelly::meshes, jelly::arkode and jelly::fit add a source to the
// program that calls theirs before main; a program linked without CMake calls them itself.
void register_io_component();
void register_meshes_component();  // the component meshes' (assimp's mesh files)
void register_arkode_component();  // the component arkode's (its two integrators)
void register_fit_component();     // the component fit's
void register_viewer_component();  // the viewer layer's (viewer/), when the program links it

}  // namespace jelly
