#pragma once
// The triangle surface a person sees of a body: triangles over vertices that follow the
// particles, each vertex a fixed weighted sum of particle positions (a particle itself, or a point
// embedded in a lattice cell with trilinear weights).
#include <array>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

using Triangle = std::array<int, 3>;
using RowMatrixX3 = Eigen::Matrix<Real, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct Surface {
  std::vector<Triangle> triangles;  // vertex indices, counter-clockwise seen from outside
  // Vertex v = sum over k in [offsets[v], offsets[v + 1]) of weights[k] * x[particles[k]].
  std::vector<int> offsets{0};
  std::vector<int> particles;
  std::vector<Real> weights;

  int num_vertices() const { return static_cast<int>(offsets.size()) - 1; }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
  bool empty() const { return triangles.empty(); }
  // A vertex that is particle p itself.
  void add_particle_vertex(int p);
  // A vertex that is a weighted sum of particles (weights sum to 1).
  void add_vertex(const int* vertex_particles, const Real* vertex_weights, int count);
  // Adds `shift` to every particle index (a body appended after others).
  void shift_particles(int shift);

  Vec3 vertex(const VecX& x, int v) const;
  // All vertex positions, one row each.
  void vertices(const VecX& x, RowMatrixX3& out) const;
  // Throws InputError unless every index is in range and every vertex has weights.
  void validate(int num_particles, const std::string& field) const;
};

}  // namespace jelly
