#pragma once
// An OpenGL 3.3 core context without a window or a display server, through EGL: Mesa's
// surfaceless platform first, then the default display with a 1x1 pbuffer. It is current on the
// creating thread while it lives; draw into a RenderTarget.
#include <string>

namespace jelly::viewer {

class OffscreenContext {
 public:
  // Throws std::runtime_error saying what EGL could not do.
  OffscreenContext();
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  // GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) ...".
  std::string description() const;
  // "surfaceless" or "pbuffer".
  const std::string& platform() const { return platform_; }

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* surface_ = nullptr;
  std::string platform_;
};

}  // namespace jelly::viewer
