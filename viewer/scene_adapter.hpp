#pragma once
// THE one place where the viewer (and `jelly export`) learns what jelly's model does not yet say
// itself: each body's render surface and each terrain's mesh and pose. Until the bodies API
// lands (core/surface.hpp, Model::bodies, Terrain::render_mesh() and pose(t): COORDINATION.md),
// a model of n^3 particles is the seed cube, whose surface is its lattice boundary faces, and
// the meshes of the plane and elevator terrains are made here. Switching to that API changes
// this file and its .cpp only: BodySurface has the fields and methods of jelly::Surface.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <jelly/core/model.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/solvers/contact/contact_solver.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly::viewer {

// A body's name, its particles and the triangle surface a person sees of it.
struct BodySurface {
  std::string name;  // as in the HDF5 file: /particles/<name>
  int first_particle = 0, num_particles = 0;
  std::vector<std::array<int, 3>> triangles;  // vertex indices, CCW seen from outside
  // Vertex v = sum over k in [offsets[v], offsets[v + 1]) of weights[k] * x[particles[k]]
  // (particle indices global).
  std::vector<int> offsets{0};
  std::vector<int> particles;
  std::vector<Real> weights;

  int num_vertices() const { return static_cast<int>(offsets.size()) - 1; }
  Vec3 vertex(const VecX& x, int v) const;
  // All vertex positions, [3 V] each, no allocation.
  void vertices(const VecX& x, float* out) const;
  void vertices(const VecX& x, double* out) const;
};

// The bodies of `model` with their surfaces. Now: one body "jelly"; when the particle count is
// n^3 (n >= 2) its surface is the cube's lattice boundary (2 (n - 1)^2 triangles per face,
// particle (i, j, k) at index (i n + j) n + k), else it has no triangles.
std::vector<BodySurface> body_surfaces(const Model& model);

// A terrain's shape in its own frame.
struct TerrainMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // CCW seen from outside (the side particles stay)
};
// An infinite plane becomes a square of half-size `extent` around the foot of `focus`; an
// elevator, its platform as a slab (top face at y = 0 of its frame). Other kinds: empty.
TerrainMesh terrain_mesh(const Terrain& terrain, const Vec3& focus, Real extent);
// Where the terrain's mesh is at time t.
Eigen::Isometry3d terrain_pose(const Terrain& terrain, Real t);
// Whether the terrain is an infinite plane: the ground (no separate floor grid is drawn then).
bool is_ground(const Terrain& terrain);

// The terrains a recording was made among, rebuilt from its scene (/parameters scene_json);
// empty when it has none. Throws InputError for a scene that does not parse.
Terrains recording_terrains(const Recording& recording);

}  // namespace jelly::viewer
