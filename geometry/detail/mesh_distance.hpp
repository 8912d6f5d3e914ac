#pragma once
// The exact signed distance of a closed triangle mesh (the mesh obstacle's shape): the nearest
// surface point through a bounding volume hierarchy over the triangles (closest point on each
// triangle a query cannot prune), signed by the angle-weighted pseudo-normal of the nearest
// feature (face, edge or vertex; Baerentzen and Aanaes 2005), which is exact for a closed,
// consistently oriented mesh that does not intersect itself and costs nothing beyond the search.
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly {

class MeshDistance {
 public:
  struct Query {
    Real distance = 0;            // signed: > 0 outside, < 0 inside
    Vec3 closest = Vec3::Zero();  // the nearest point of the surface
    // Outward unit normal: the gradient of the signed distance, (q - closest) / distance; on the
    // surface itself (|distance| below 1e-12 of the mesh's size) the nearest feature's
    // pseudo-normal.
    Vec3 normal = Vec3::UnitY();
    int triangle = -1;  // the nearest triangle (index into mesh().triangles)
  };

  // Where on a triangle its closest point to a query lies.
  enum class Feature { kFace, kVertexA, kVertexB, kVertexC, kEdgeAB, kEdgeBC, kEdgeCA };

  // `mesh` must have a triangle and finite vertices, and be closed, manifold and consistently
  // oriented (mesh_io's checks and a closed topology); oriented outwards, or the sign flips.
  explicit MeshDistance(TriangleMesh mesh);

  // `hint`: a triangle likely near q (the previous query's, for a stream of nearby points); it
  // only bounds the search, the answer is the same with any hint.
  Query query(const Vec3& q, int hint = -1) const;
  // The unsigned distance, the nearest point and its triangle and feature (the tree only).
  Real unsigned_distance(const Vec3& q, Vec3* closest = nullptr, int* triangle = nullptr,
                         Feature* feature = nullptr, int hint = -1) const;

  const TriangleMesh& mesh() const { return mesh_; }

  // The closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5) and
  // the feature it lies on; a triangle of zero area is treated as its three edges.
  static Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                  Feature* feature = nullptr);

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
  Vec3 pseudo_normal(int triangle, Feature feature) const;

  TriangleMesh mesh_;
  std::vector<Tri> tris_;  // in tree order
  std::vector<Node> nodes_;
  // Pseudo-normals (not normalized): per triangle its face normal and its edges' (ab, bc, ca:
  // the sum of the two faces' unit normals), per vertex the sum of its faces' unit normals
  // weighted by their angles there.
  std::vector<Vec3> face_normal_;
  std::vector<std::array<Vec3, 3>> edge_normal_;
  std::vector<Vec3> vertex_normal_;
  Real on_surface_ = 0;  // |distance| below which the normal is the feature's
};

}  // namespace jelly
