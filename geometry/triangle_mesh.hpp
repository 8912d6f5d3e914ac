#pragma once
// A triangle mesh: vertex positions and triangles over them (counter-clockwise seen from
// outside), for obstacles, render shapes and the meshes bodies are made from.
#include <string>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

// A triangle mesh: vertices and triangles over them (counter-clockwise seen from outside).
struct TriangleMesh {
  std::vector<Vec3> vertices;       // m
  std::vector<Triangle> triangles;  // vertex indices

  // The number of vertices.
  int num_vertices() const { return static_cast<int>(vertices.size()); }
  // The number of triangles.
  int num_triangles() const { return static_cast<int>(triangles.size()); }
  // The box around the vertices: an Eigen::AlignedBox3d (<Eigen/Geometry>).
  Eigen::AlignedBox<Real, 3> bounds() const;
  // The surface's area, and the volume it encloses (divergence theorem: the sum of
  // a . (b x c) / 6 over the triangles; negative when they face inwards).
  Real area() const;
  Real enclosed_volume() const;  // m^3
  // Adds a quad as two triangles a-b-c, a-c-d.
  void add_quad(int a, int b, int c, int d);
  // Appends `other`.
  void append(const TriangleMesh& other);
};

// Meshes of simple shapes, centred at the origin, for drawing and tests.
TriangleMesh box_mesh(const Vec3& size);
// A square of side `size` in the plane through the origin with the given unit normal.
TriangleMesh square_mesh(const Vec3& normal, Real size);
// A sphere of `rings` x `segments` quads (the poles' as triangles).
TriangleMesh sphere_mesh(Real radius, int rings = 16, int segments = 32);
// Along y, from -height/2 to +height/2, capped.
TriangleMesh cylinder_mesh(Real radius, Real height, int segments = 32);
// Along y: a cylinder of the given height between two hemispheres.
TriangleMesh capsule_mesh(Real radius, Real height, int rings = 8, int segments = 32);

}  // namespace jelly
