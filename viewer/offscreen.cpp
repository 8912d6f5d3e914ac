#include <jelly/viewer/offscreen.hpp>

#include <cstring>
#include <stdexcept>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <jelly/viewer/detail/gl.hpp>

namespace jelly::viewer {

namespace {

std::string egl_error() {
  const EGLint e = eglGetError();
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    default:
      return "EGL error " + std::to_string(e);
  }
}

bool has_extension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + n, name)) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

}  // namespace

OffscreenContext::OffscreenContext() {
  EGLDisplay display = EGL_NO_DISPLAY;
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display != nullptr) {
      display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      EGLint major = 0, minor = 0;
      if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor))
        platform_ = "surfaceless";
      else
        display = EGL_NO_DISPLAY;
    }
  }
  if (display == EGL_NO_DISPLAY) {
    display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor))
      throw std::runtime_error(
          "no EGL display for offscreen rendering (" + egl_error() +
          "): install Mesa's EGL and drivers (libegl1, libegl-mesa0, libgl1-mesa-dri)");
    platform_ = "pbuffer";
  }
  display_ = display;
  if (!eglBindAPI(EGL_OPENGL_API))
    throw std::runtime_error("EGL cannot bind the OpenGL API: " + egl_error());

  const bool surfaceless = platform_ == "surfaceless";
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE,
                                      surfaceless ? 0 : EGL_PBUFFER_BIT,
                                      EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT,
                                      EGL_RED_SIZE,
                                      8,
                                      EGL_GREEN_SIZE,
                                      8,
                                      EGL_BLUE_SIZE,
                                      8,
                                      EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &count) || count < 1)
    throw std::runtime_error("no EGL configuration with OpenGL (" + egl_error() + ")");
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                       3,
                                       EGL_CONTEXT_MINOR_VERSION,
                                       3,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                       EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT)
    throw std::runtime_error("EGL cannot create an OpenGL 3.3 core context (" + egl_error() + ")");
  context_ = context;
  EGLSurface surface = EGL_NO_SURFACE;
  if (!surfaceless) {
    const EGLint pbuffer_attributes[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    surface = eglCreatePbufferSurface(display, config, pbuffer_attributes);
    if (surface == EGL_NO_SURFACE)
      throw std::runtime_error("EGL cannot create a pbuffer (" + egl_error() + ")");
    surface_ = surface;
  }
  if (!eglMakeCurrent(display, surface, surface, context))
    throw std::runtime_error("EGL cannot make the context current (" + egl_error() + ")");
}

OffscreenContext::~OffscreenContext() {
  auto display = static_cast<EGLDisplay>(display_);
  if (display == EGL_NO_DISPLAY || display == nullptr) return;
  eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_) eglDestroySurface(display, static_cast<EGLSurface>(surface_));
  if (context_) eglDestroyContext(display, static_cast<EGLContext>(context_));
  eglTerminate(display);
}

std::string OffscreenContext::description() const {
  const auto text = [](GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return std::string(s ? s : "?");
  };
  return text(GL_RENDERER) + ", OpenGL " + text(GL_VERSION) + " (EGL " + platform_ + ")";
}

}  // namespace jelly::viewer
