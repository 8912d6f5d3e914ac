#include <jelly/viewer/detail/gl_program.hpp>

#include <stdexcept>

namespace jelly::detail {
namespace {

GLuint compile_gl_shader(GLenum type, const char* source, const std::string& what) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error(what + " shader does not compile: " + log);
  }
  return shader;
}

}  // namespace

GLuint link_gl_program(const char* vertex, const char* fragment, const std::string& what) {
  const GLuint vs = compile_gl_shader(GL_VERTEX_SHADER, vertex, what);
  GLuint fs = 0;
  try {
    fs = compile_gl_shader(GL_FRAGMENT_SHADER, fragment, what);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    throw std::runtime_error(what + " program does not link: " + log);
  }
  return program;
}

}  // namespace jelly::detail
