#pragma once
// The generalized winding number of a triangle mesh (Jacobson, Kavan and Sorkine-Hornung 2013):
// the solid angle the mesh subtends at a point over 4 pi. It is 1 inside a closed mesh oriented
// outwards and 0 outside, changes little across a small hole, and counts the layers where parts
// overlap (2 inside two intersecting spheres): "inside" is w >= 1/2. Evaluated in O(log n) per
// point with a tree of second-order expansions (Barill, Dickson, Schmidt, Levin and Jacobson
// 2018).
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly {

class WindingNumber {
 public:
  // `accuracy` is Barill et al.'s beta: a cluster of triangles is replaced by its expansion when
  // the point is farther than beta times the cluster's radius from its centre (2: errors below
  // 1e-2 near the mesh and far smaller away from it; larger is more exact and slower).
  explicit WindingNumber(const TriangleMesh& mesh, Real accuracy = 2);

  // w(q), fast.
  Real operator()(const Vec3& q) const;
  // w(q) summed over every triangle (reference for tests).
  Real exact(const Vec3& q) const;
  // Whether a triangle comes within `distance` of q.
  bool near_surface(const Vec3& q, Real distance) const;

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    Vec3 centre;                   // area-weighted centroid of the node's triangles
    Vec3 area_normal;              // sum of area x unit normal
    Eigen::Matrix3d first_moment;  // sum of area (centroid - centre) normal^T
    // Per normal component k: sum of area normal_k E[(x - centre)(x - centre)^T] over each
    // triangle (x uniform on it).
    std::array<Eigen::Matrix3d, 3> second_moment;
    Real area = 0;  // of the node's triangles
    // At least the largest distance from centre to a vertex of the node's triangles.
    Real radius = 0;
    int begin = 0, end = 0;  // the node's triangles, [begin, end) of triangles_
    int left = -1, right = -1;
  };
  struct Tri {
    Vec3 a, b, c;
  };

  int build(int begin, int end, std::vector<int>& order, const std::vector<Vec3>& centroids);
  static Real solid_angle(const Tri& t, const Vec3& q);
  static Real squared_distance(const Tri& t, const Vec3& q);

  std::vector<Tri> triangles_;
  std::vector<Node> nodes_;
  Real accuracy_;
};

}  // namespace jelly
