#pragma once
// Makes the RenderScene of a model among terrains and refreshes it for a state: body surfaces
// (scene_adapter.hpp), particles, springs, terrain meshes with their poses, and a floor grid when
// no terrain is a floor. update() allocates nothing.
#include <memory>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/viewer/render_scene.hpp>
#include <jelly/viewer/scene_adapter.hpp>

namespace jelly::viewer {

class SceneBuilder {
 public:
  // `focus` is where the action is (the bodies' initial bounds, or their bounds over a whole
  // recording): infinite planes are drawn as squares around it. The builder keeps its own
  // terrains (the caller's may live on another thread).
  SceneBuilder(const Model& model, std::vector<BodySurface> surfaces, Terrains terrains,
               const Vec3& focus_lo, const Vec3& focus_hi);
  // The model's own bodies (body_surfaces).
  SceneBuilder(const Model& model, Terrains terrains, const Vec3& focus_lo, const Vec3& focus_hi)
      : SceneBuilder(model, body_surfaces(model), std::move(terrains), focus_lo, focus_hi) {}

  // A scene of this model's topology at state (x, t); its `topology` is new.
  RenderScene make_scene(const VecX& x, Real t) const;
  // Positions and poses of `scene` (made by make_scene) for state (x, t).
  void update(const VecX& x, Real t, RenderScene& scene) const;

  const std::vector<BodySurface>& surfaces() const { return surfaces_; }
  const Terrains& terrains() const { return terrains_; }
  int num_particles() const { return num_particles_; }

 private:
  int num_particles_ = 0;
  std::vector<BodySurface> surfaces_;
  Terrains terrains_;
  std::vector<TriangleMesh> meshes_;
  std::vector<std::array<int, 2>> springs_;
  std::vector<float> rest_length_;
  std::vector<int> type_;
  float particle_radius_ = 0.05f;
  Vec3f focus_ = Vec3f::Zero();
  float extent_ = 0;
  bool floor_ = false;
  float floor_height_ = 0;
};

// The bounds of every frame's particles (for a recording's focus and camera).
void bounds_of(const std::vector<VecX>& frames, Vec3& lo, Vec3& hi);
void bounds_of(const VecX& x, Vec3& lo, Vec3& hi);

}  // namespace jelly::viewer
