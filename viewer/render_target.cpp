#include <jelly/viewer/render_target.hpp>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include <jelly/viewer/detail/gl.hpp>
#include <jelly/viewer/detail/gl_program.hpp>

namespace jelly::viewer {

namespace {

// A triangle covering the whole viewport, made from gl_VertexID (no vertex buffer).
constexpr const char* kFxaaVertex = R"(#version 330 core
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1)) - 1.0;
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

// Fast approximate anti-aliasing: a pixel whose 3x3 corners differ in luma by more than a
// threshold (relative to the brightest, with a floor for dark places) lies on an edge; it is
// replaced by the mean of samples taken along the edge's direction (perpendicular to the luma
// gradient), two near ones or, when that stays within the neighbourhood's luma range, four
// reaching further. Pixels off edges are copied unchanged.
constexpr const char* kFxaaFragment = R"(#version 330 core
uniform sampler2D u_image;
out vec4 o_color;
const float kEdgeRelative = 0.125, kEdgeFloor = 0.0625;
const float kReduceScale = 0.125, kReduceFloor = 1.0 / 128.0, kReach = 8.0;
float luma(vec3 c) { return dot(c, vec3(0.299, 0.587, 0.114)); }
vec3 at(vec2 uv) { return texture(u_image, uv).rgb; }
void main() {
  ivec2 size = textureSize(u_image, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 centre = texelFetch(u_image, p, 0).rgb;
  ivec2 top = size - 1;
  float nw = luma(texelFetch(u_image, clamp(p + ivec2(-1, 1), ivec2(0), top), 0).rgb);
  float ne = luma(texelFetch(u_image, clamp(p + ivec2(1, 1), ivec2(0), top), 0).rgb);
  float sw = luma(texelFetch(u_image, clamp(p + ivec2(-1, -1), ivec2(0), top), 0).rgb);
  float se = luma(texelFetch(u_image, clamp(p + ivec2(1, -1), ivec2(0), top), 0).rgb);
  float m = luma(centre);
  float lo = min(m, min(min(nw, ne), min(sw, se)));
  float hi = max(m, max(max(nw, ne), max(sw, se)));
  if (hi - lo < max(kEdgeFloor, kEdgeRelative * hi)) {
    o_color = vec4(centre, 1.0);
    return;
  }
  // The luma gradient (y up) and the edge's direction across it.
  float gx = (ne + se) - (nw + sw), gy = (nw + ne) - (sw + se);
  vec2 along = vec2(-gy, gx);
  float reduce = max(0.25 * (nw + ne + sw + se) * kReduceScale, kReduceFloor);
  along = clamp(along / (min(abs(along.x), abs(along.y)) + reduce), vec2(-kReach), vec2(kReach));
  vec2 texel = 1.0 / vec2(size);
  vec2 uv = gl_FragCoord.xy * texel;
  vec2 d = along * texel;
  vec3 near = 0.5 * (at(uv - d / 6.0) + at(uv + d / 6.0));
  vec3 far = 0.5 * near + 0.25 * (at(uv - 0.5 * d) + at(uv + 0.5 * d));
  float l = luma(far);
  o_color = vec4((l < lo || l > hi) ? near : far, 1.0);
}
)";

GLuint link_fxaa_program() {
  const GLuint program =
      detail::link_gl_program(kFxaaVertex, kFxaaFragment, "RenderTarget: the FXAA");
  glUseProgram(program);
  glUniform1i(glGetUniformLocation(program, "u_image"), 0);
  glUseProgram(0);
  return program;
}

}  // namespace

RenderTarget::RenderTarget(int width, int height, int samples, bool fxaa)
    : width_(width), height_(height), fxaa_(fxaa), fxaa_rect_{0, 0, width, height} {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("RenderTarget: size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is not positive");
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = fxaa ? 1 : std::clamp(samples, 1, std::max(1, static_cast<int>(max_samples)));
  if (fxaa_) {
    fxaa_program_ = link_fxaa_program();
    glGenVertexArrays(1, &fxaa_vao_);
  }
  allocate();
}

RenderTarget::~RenderTarget() {
  release();
  if (fxaa_program_ != 0) glDeleteProgram(fxaa_program_);
  if (fxaa_vao_ != 0) glDeleteVertexArrays(1, &fxaa_vao_);
}

void RenderTarget::allocate() {
  glGenFramebuffers(1, &draw_fbo_);
  glGenRenderbuffers(1, &depth_rbo_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_rbo_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0,
                                   GL_DEPTH_COMPONENT24, width_, height_);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  if (fxaa_) {
    // A texture the FXAA pass samples, with bilinear taps between pixels and edges clamped.
    glGenTextures(1, &color_texture_);
    glBindTexture(GL_TEXTURE_2D, color_texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width_, height_, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_texture_, 0);
  } else {
    glGenRenderbuffers(1, &color_rbo_);
    glBindRenderbuffer(GL_RENDERBUFFER, color_rbo_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0, GL_RGBA8, width_,
                                     height_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rbo_);
  }
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rbo_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("RenderTarget: the multisampled framebuffer is incomplete");

  glGenFramebuffers(1, &resolve_fbo_);
  glGenRenderbuffers(1, &resolve_rbo_);
  glBindRenderbuffer(GL_RENDERBUFFER, resolve_rbo_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width_, height_);
  glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_rbo_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("RenderTarget: the resolve framebuffer is incomplete");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void RenderTarget::release() {
  glDeleteFramebuffers(1, &draw_fbo_);
  glDeleteFramebuffers(1, &resolve_fbo_);
  glDeleteRenderbuffers(1, &color_rbo_);
  glDeleteRenderbuffers(1, &depth_rbo_);
  glDeleteRenderbuffers(1, &resolve_rbo_);
  if (color_texture_ != 0) glDeleteTextures(1, &color_texture_);
  draw_fbo_ = resolve_fbo_ = color_rbo_ = depth_rbo_ = resolve_rbo_ = color_texture_ = 0;
}

void RenderTarget::resize(int width, int height) {
  if (width == width_ && height == height_) return;
  if (width <= 0 || height <= 0) return;  // a minimised window: keep the old buffers
  release();
  width_ = width;
  height_ = height;
  fxaa_rect_ = {0, 0, width, height};
  allocate();
}

void RenderTarget::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glViewport(0, 0, width_, height_);
}

void RenderTarget::resolve() {
  if (fxaa_) {
    // FXAA runs only over the rectangle that holds the silhouettes (its cost per pixel is
    // measured in docs/viewer.md); the rest is copied.
    const auto [x0, y0, x1, y1] = fxaa_rect_;
    const bool whole = x0 <= 0 && y0 <= 0 && x1 >= width_ && y1 >= height_;
    if (!whole) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
      glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                        GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
    glViewport(0, 0, width_, height_);
    const GLboolean depth = glIsEnabled(GL_DEPTH_TEST);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    if (whole) {
      glDisable(GL_SCISSOR_TEST);
    } else {
      glEnable(GL_SCISSOR_TEST);
      glScissor(x0, y0, std::max(x1 - x0, 0), std::max(y1 - y0, 0));
    }
    glUseProgram(fxaa_program_);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, color_texture_);
    glBindVertexArray(fxaa_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    glDisable(GL_SCISSOR_TEST);
    if (depth) glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void RenderTarget::read_rgb(std::vector<std::uint8_t>& out) {
  // Read as RGBA, the framebuffer's own format (a plain copy in Mesa, where RGB takes a
  // per-pixel conversion path), then dropped to RGB while the rows are turned top-down.
  const size_t row = static_cast<size_t>(width_) * 3, row4 = static_cast<size_t>(width_) * 4;
  const size_t size = row * static_cast<size_t>(height_);
  if (rows_.size() != row4 * static_cast<size_t>(height_))
    rows_.resize(row4 * static_cast<size_t>(height_));
  if (out.size() != size) out.resize(size);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rows_.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  for (int y = 0; y < height_; ++y) {
    const std::uint8_t* from = rows_.data() + row4 * static_cast<size_t>(height_ - 1 - y);
    std::uint8_t* to = out.data() + row * static_cast<size_t>(y);
    for (int x = 0; x < width_; ++x, from += 4, to += 3) {
      to[0] = from[0];
      to[1] = from[1];
      to[2] = from[2];
    }
  }
}

void RenderTarget::blit_to(unsigned target) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, target);
}

}  // namespace jelly::viewer
