#pragma once
// The exact signed distance of a closed triangle mesh (the mesh obstacle's shape): the nearest
// surface point through a bounding volume hierarchy over the triangles (closest point on each
// triangle a query cannot prune), signed by the generalized winding number (negative inside).
#include <cstdint>

#include <jelly/geometry/triangle_mesh.hpp>
#include <jelly/geometry/winding_number.hpp>

namespace jelly {

class MeshDistance {
 public:
  struct Query {
    Real distance = 0;            // signed: > 0 outside, < 0 inside
    Vec3 closest = Vec3::Zero();  // the nearest point of the surface
    // Outward unit normal: the gradient of the signed distance, (q - closest) / distance; on the
    // surface itself (|distance| below 1e-12 of the mesh's size) the nearest triangle's normal.
    Vec3 normal = Vec3::UnitY();
    int triangle = -1;  // the nearest triangle (index into mesh().triangles)
  };

  // `mesh` must have a triangle and finite vertices (mesh_io's checks); it should be closed and
  // oriented outwards (the winding number is 1 inside), which the caller checks.
  explicit MeshDistance(TriangleMesh mesh);

  Query query(const Vec3& q) const;
  // The unsigned distance and the nearest point, without the sign (the tree only).
  Real unsigned_distance(const Vec3& q, Vec3* closest = nullptr, int* triangle = nullptr) const;
  // Whether q is inside (winding number >= 1/2).
  bool inside(const Vec3& q) const { return winding_(q) >= 0.5; }

  const TriangleMesh& mesh() const { return mesh_; }
  int tree_nodes() const { return static_cast<int>(nodes_.size()); }

  // The closest point of triangle abc to q (Ericson, Real-Time Collision Detection 5.1.5);
  // a triangle of zero area is treated as its longest edge.
  static Vec3 closest_on_triangle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c);

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    int begin = 0, end = 0;     // leaf: triangles [begin, end) of tris_
    int left = -1, right = -1;  // inner node: children
  };
  struct Tri {
    Vec3 a, b, c;
    int index;  // in mesh_.triangles
  };

  int build(int begin, int end);

  TriangleMesh mesh_;
  std::vector<Tri> tris_;  // in tree order
  std::vector<Node> nodes_;
  WindingNumber winding_;
  Real on_surface_ = 0;  // |distance| below which the normal is the triangle's
};

}  // namespace jelly
