#pragma once
// What the renderer draws (renderer.hpp), as plain single-precision data: the bodies' surfaces
// with their vertex positions, the particles and springs, the terrains' meshes with their poses,
// a floor grid and the mouse drag. SceneBuilder (scene_builder.hpp) makes one and refreshes its
// positions in place every frame; `topology` changes whenever anything else does.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace jelly::viewer {

using Vec3f = Eigen::Vector3f;
using Mat4f = Eigen::Matrix4f;

// One body's render surface.
struct SurfaceView {
  std::string name;
  std::vector<std::array<int, 3>> triangles;  // vertex indices, CCW seen from outside
  std::vector<float> positions;               // [3 V] this frame
  Vec3f color{0.85f, 0.13f, 0.22f};           // sRGB, of its surface and its particles
  int first_particle = 0, num_particles = 0;  // its range of RenderScene::particles
  int num_vertices() const { return static_cast<int>(positions.size() / 3); }
};

// One terrain: a fixed mesh in the terrain's own frame and where that frame is now.
struct TerrainView {
  std::string name;
  std::vector<float> vertices;  // [3 V] in the terrain's frame
  std::vector<std::array<int, 3>> triangles;
  Mat4f pose = Mat4f::Identity();
  Vec3f color{0.63f, 0.65f, 0.67f};
  // Finite obstacles (a sphere, a bowl, the elevator) cast shadows and are drawn plainly
  // shaded; the ground (planes) casts none and carries the grid.
  bool casts_shadow = false;
};

enum class SpringColoring { kType, kStrain };

struct RenderScene {
  // Changes whenever anything but positions, poses, drag and display flags changes.
  unsigned long topology = 0;

  std::vector<SurfaceView> bodies;
  std::vector<TerrainView> terrains;

  std::vector<float> particles;  // [3 N] this frame
  float particle_radius = 0.05f;
  // Springs, fixed: particle pairs, rest lengths, types (0 structural, 1 shear, 2 bending).
  std::vector<std::array<int, 2>> springs;
  std::vector<float> spring_rest_length;
  std::vector<int> spring_type;

  bool show_surfaces = true;
  bool show_particles = false;
  bool show_springs = false;
  bool show_structural_only = true;  // with show_springs: only type 0
  SpringColoring spring_coloring = SpringColoring::kType;

  // Where the action is and how far the ground reaches from it: beyond half that distance the
  // ground fades into the horizon (0: no fading).
  Vec3f focus = Vec3f::Zero();
  float ground_extent = 0;
  // A grid on the plane y = floor_height (drawn only, no contact), ground_extent wide.
  bool floor = false;
  float floor_height = 0;

  // The mouse drag: a line from the dragged particle to its target.
  bool drag = false;
  Vec3f drag_from = Vec3f::Zero(), drag_to = Vec3f::Zero();

  // Axis-aligned bounds of the particles this frame (lo > hi when there are none).
  void particle_bounds(Vec3f& lo, Vec3f& hi) const;
};

}  // namespace jelly::viewer
