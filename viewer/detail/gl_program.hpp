#pragma once
// Compiling and linking an OpenGL program from vertex and fragment sources, for every renderer of
// the viewer. The current context must be an OpenGL 3.3 core one.
#include <string>

#include <jelly/viewer/detail/gl.hpp>

namespace jelly::detail {

// The linked program; throws std::runtime_error "<what> shader does not compile: <log>" or
// "<what> program does not link: <log>" (what names the program for the user, e.g.
// "renderer: the grid"). The shader objects are deleted either way.
GLuint link_gl_program(const char* vertex, const char* fragment, const std::string& what);

}  // namespace jelly::detail
