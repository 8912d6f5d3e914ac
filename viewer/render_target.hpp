#pragma once
// An offscreen framebuffer of a given size: multisampled colour and depth to draw into, resolved
// into a single-sampled colour buffer that is read back (video, screenshots) or copied to a
// window. The window and `jelly render` draw through the same target, so they make the same
// pixels. Needs a current OpenGL 3.3 core context.
#include <cstdint>
#include <vector>

namespace jelly::viewer {

class RenderTarget {
 public:
  // samples: 1 = no multisampling; more is clamped to what the implementation offers.
  RenderTarget(int width, int height, int samples = 4);
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  // Reallocates the buffers when the size differs.
  void resize(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

  // Binds the multisampled framebuffer for drawing and sets the viewport to the whole of it.
  void bind();
  // Resolves the multisampled buffer into the single-sampled one.
  void resolve();
  // The resolved pixels as RGB bytes, rows top to bottom; `out` is resized only when needed.
  void read_rgb(std::vector<std::uint8_t>& out);
  // Copies the resolved pixels to framebuffer `target` (0: the window's) of the same size.
  void blit_to(unsigned target);

 private:
  void allocate();
  void release();

  int width_ = 0, height_ = 0, samples_ = 1;
  unsigned draw_fbo_ = 0, color_rbo_ = 0, depth_rbo_ = 0;
  unsigned resolve_fbo_ = 0, resolve_rbo_ = 0;
  std::vector<std::uint8_t> rows_;  // bottom-up RGBA scratch
};

}  // namespace jelly::viewer
