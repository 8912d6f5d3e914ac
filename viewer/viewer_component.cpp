#include <jelly/core/components.hpp>

// The viewer component: what `jelly list` says of it depends on the parts this build has
// (viewer/CMakeLists.txt): the exports always, offscreen rendering and the window with their
// packages.
namespace jelly {

void register_viewer_component() {
#if defined(JELLY_VIEWER_WITH_WINDOW)
  register_component({"viewer",
                      "live window (jelly view), offscreen rendering to video (jelly render), "
                      "exports to OBJ, PC2 and glTF (OpenGL, EGL, GLFW, Dear ImGui)"});
#elif defined(JELLY_VIEWER_WITH_RENDER)
  register_component({"viewer",
                      "offscreen rendering to video (jelly render), exports to OBJ, PC2 and "
                      "glTF; no window (GLFW or Dear ImGui were not found)"});
#else
  register_component({"viewer", "exports to OBJ, PC2 and glTF; no rendering (OpenGL not built)"});
#endif
}

}  // namespace jelly
