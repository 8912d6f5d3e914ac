#pragma once
// An offscreen framebuffer of a given size: multisampled colour and depth to draw into, resolved
// into a single-sampled colour buffer that is read back (video, screenshots) or copied to a
// window. The window and `jelly render` draw through the same target, so they make the same
// pixels. With FXAA the drawing is single-sampled and the resolve is a post-process pass that
// blends each pixel on a contrast edge along the edge (in place of multisampling, which is
// llvmpipe's largest cost). Needs a current OpenGL 3.3 core context.
#include <array>
#include <cstdint>
#include <vector>

namespace jelly::viewer {

class RenderTarget {
 public:
  // samples: 1 = no multisampling; more is clamped to what the implementation offers.
  // fxaa: draw single-sampled (samples is then 1) and smooth the edges when resolving.
  RenderTarget(int width, int height, int samples = 4, bool fxaa = false);
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  // Reallocates the buffers when the size differs.
  void resize(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }
  bool fxaa() const { return fxaa_; }

  // Binds the multisampled framebuffer for drawing and sets the viewport to the whole of it.
  void bind();
  // Resolves the multisampled buffer into the single-sampled one (with FXAA: a copy, then the
  // FXAA pass over `fxaa_rect`).
  void resolve();
  // FXAA: the rectangle (x0, y0, x1, y1 in pixels from the bottom left) the pass smooths, where
  // the silhouettes are (Renderer::edge_rect); the rest is copied as drawn. Default and after a
  // resize: the whole picture.
  void set_fxaa_rect(const std::array<int, 4>& rect) { fxaa_rect_ = rect; }
  // The resolved pixels as RGB bytes, rows top to bottom; `out` is resized only when needed.
  void read_rgb(std::vector<std::uint8_t>& out);
  // Copies the resolved pixels to framebuffer `target` (0: the window's) of the same size.
  void blit_to(unsigned target);

 private:
  void allocate();
  void release();

  int width_ = 0, height_ = 0, samples_ = 1;
  bool fxaa_ = false;
  std::array<int, 4> fxaa_rect_{0, 0, 0, 0};
  unsigned draw_fbo_ = 0, color_rbo_ = 0, depth_rbo_ = 0;
  unsigned color_texture_ = 0;                // FXAA: the drawn image, sampled by the pass
  unsigned fxaa_program_ = 0, fxaa_vao_ = 0;  // FXAA: made once, kept over resizes
  unsigned resolve_fbo_ = 0, resolve_rbo_ = 0;
  std::vector<std::uint8_t> rows_;  // bottom-up RGBA scratch
};

}  // namespace jelly::viewer
