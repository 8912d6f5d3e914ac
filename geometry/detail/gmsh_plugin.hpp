#pragma once
// Gmsh (with OpenCASCADE, FLTK and X11 behind it) takes longer to load than a whole short run,
// and only tetrahedralize needs it. So its part lives in a library of its own, libjelly_gmsh
// (geometry/detail/gmsh/), which libjelly loads beside itself on first use: a program that never
// meshes never loads Gmsh. A static libjelly, or a build with JELLY_GMSH_PLUGIN=OFF, links it in
// instead. This header is the contract between the two; internal to geometry/.
#include <string>

#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly::detail {

// Fills `surface` (already checked closed and manifold) with tetrahedra, remeshing its
// triangles at `size` first when size > 0, as tetrahedralize documents. Throws InputError naming
// `field` = `value` with Gmsh's reason when Gmsh fails.
using GmshFill = TetMesh (*)(const TriangleMesh& surface, Real size, const std::string& field,
                             const std::string& value);

// What the plugin hands over. `abi` changes whenever this struct or GmshFill does, and
// `version` is the plugin's JELLY_VERSION: a plugin of another build is refused, not called.
struct GmshPlugin {
  int abi = 0;
  const char* version = "";
  GmshFill fill = nullptr;
};
inline constexpr int kGmshPluginAbi = 1;
// The plugin's one exported symbol: extern "C" const GmshPlugin* jelly_gmsh_plugin().
inline constexpr const char* kGmshPluginSymbol = "jelly_gmsh_plugin";
inline constexpr const char* kGmshPluginFile = "libjelly_gmsh.so";

// The plugin's fill function, loaded on the first call (thread-safe). Throws Error saying what
// is missing (a build without Gmsh, the plugin file not found beside libjelly, a plugin of
// another build) and how to get it.
GmshFill gmsh_fill();
// "" when gmsh_fill() would succeed, otherwise why not; loads the plugin to find out.
std::string gmsh_unavailable_reason();

}  // namespace jelly::detail
