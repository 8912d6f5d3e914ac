#pragma once
// Draws a RenderScene seen by a Camera into whatever framebuffer is bound: lit surfaces with
// shadows from a directional light (a shadow map fitted to the bodies and the obstacles), the
// ground with a grid, obstacles in a plain shaded material,
// particles as shaded spheres, springs coloured by type or strain, the drag line and a sky
// gradient. The live window, the screenshot and `jelly render` share it. Needs a current
// OpenGL 3.3 core context; GPU buffers are made when the scene's topology changes and only
// refilled in place otherwise (no allocation per frame).
#include <array>
#include <memory>

#include <jelly/viewer/camera.hpp>
#include <jelly/viewer/render_scene.hpp>

namespace jelly::viewer {

struct RenderOptions {
  bool shadows = true;
  int shadow_map_size = 1024;
  bool grid = true;  // grid lines on the ground (planes, the floor); never on obstacles
  Vec3f light_direction = Vec3f(0.35f, 1.0f, 0.25f);  // towards the light
  Vec3f sky_top{0.50f, 0.64f, 0.80f};
  Vec3f sky_bottom{0.86f, 0.89f, 0.93f};
};

class Renderer {
 public:
  // Compiles the shaders; throws std::runtime_error with the driver's log when one fails.
  explicit Renderer(RenderOptions options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws into the bound framebuffer, whose drawable size is width x height (the viewport is
  // set to it). Restores the framebuffer binding it found.
  void draw(const RenderScene& scene, const Camera& camera, int width, int height);

  // The rectangle of the last drawn picture (x0, y0, x1, y1 in pixels from its bottom left) that
  // holds the bodies and the finite obstacles: where their silhouettes are (RenderTarget's FXAA
  // pass is limited to it).
  std::array<int, 4> edge_rect() const { return edge_rect_; }

  RenderOptions& options() { return options_; }
  const RenderOptions& options() const { return options_; }

 private:
  struct Gpu;
  RenderOptions options_;
  std::unique_ptr<Gpu> gpu_;
  std::array<int, 4> edge_rect_{0, 0, 0, 0};
};

}  // namespace jelly::viewer
