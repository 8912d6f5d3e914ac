#pragma once
// OpenGL 3.3 core entry points, linked directly from libOpenGL (GLVND dispatches each call to the
// current context, whether GLX made it (the window) or EGL (offscreen)): no loader.
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
