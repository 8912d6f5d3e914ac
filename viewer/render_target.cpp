#include <jelly/viewer/render_target.hpp>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include <jelly/viewer/detail/gl.hpp>

namespace jelly::viewer {

RenderTarget::RenderTarget(int width, int height, int samples) : width_(width), height_(height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("RenderTarget: size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is not positive");
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::clamp(samples, 1, std::max(1, static_cast<int>(max_samples)));
  allocate();
}

RenderTarget::~RenderTarget() { release(); }

void RenderTarget::allocate() {
  glGenFramebuffers(1, &draw_fbo_);
  glGenRenderbuffers(1, &color_rbo_);
  glGenRenderbuffers(1, &depth_rbo_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_rbo_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0, GL_RGBA8, width_,
                                   height_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_rbo_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0,
                                   GL_DEPTH_COMPONENT24, width_, height_);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rbo_);
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
  draw_fbo_ = resolve_fbo_ = color_rbo_ = depth_rbo_ = resolve_rbo_ = 0;
}

void RenderTarget::resize(int width, int height) {
  if (width == width_ && height == height_) return;
  if (width <= 0 || height <= 0) return;  // a minimised window: keep the old buffers
  release();
  width_ = width;
  height_ = height;
  allocate();
}

void RenderTarget::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glViewport(0, 0, width_, height_);
}

void RenderTarget::resolve() {
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
