#pragma once
// The one place where the viewer (and `jelly export`) reads what a body and a terrain look like:
// the bodies' render surfaces (Model::bodies, core/model.hpp) and the terrains' meshes and
// poses (Terrain::render_mesh(), pose(t)), with the viewer's own choices on top: an infinite
// plane is drawn as a square large enough for the action, and a recording whose file holds no
// bodies takes them from the scene it was made from.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <jelly/core/model.hpp>
#include <jelly/geometry/triangle_mesh.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly::viewer {

// A body's name, its particles and the triangle surface a person sees of it (global particle
// indices).
struct BodySurface : Surface {
  std::string name;  // as in the HDF5 file: /particles/<name>
  int first_particle = 0, num_particles = 0;
  std::optional<Vec3> color;  // the body's own (sRGB in [0, 1]); none: the viewer's palette

  using Surface::vertices;
  // All vertex positions, [3 V] each, no allocation.
  void vertices(const VecX& x, float* out) const;
  void vertices(const VecX& x, double* out) const;
};

// The colour (sRGB in [0, 1]) of the body at `index` when it has none of its own: a palette of
// four, the seed jelly's raspberry red first.
Vec3 palette_color(int index);

// Every body of `model` with its render surface (empty for a body without one).
std::vector<BodySurface> body_surfaces(const Model& model);
// The bodies of a recording: its model's; for a file that holds none, those of the scene it was
// made from (/parameters scene_json: the same particles in the same order), else one body
// "jelly" of all particles, with the lattice boundary of a cube when there are n^3 of them. A
// body the file gives no colour takes its scene's, if the scene gives one.
std::vector<BodySurface> recording_surfaces(const Recording& recording);

// A terrain's shape in its own frame (render_mesh()); an infinite plane becomes a square of
// half-size `extent` around the foot of `focus` instead of its 20 m one.
TriangleMesh terrain_mesh(const Terrain& terrain, const Vec3& focus, Real extent);
// Where the terrain's mesh is at time t (pose(t)).
Eigen::Isometry3d terrain_pose(const Terrain& terrain, Real t);
// Whether the terrain is an infinite plane: the ground (no separate floor grid is drawn then,
// and it casts no shadow).
bool is_ground(const Terrain& terrain);

// The terrains a recording was made among, rebuilt from its scene (/parameters scene_json);
// empty when it has none. Throws InputError for a scene that does not parse.
Terrains recording_terrains(const Recording& recording);

}  // namespace jelly::viewer
