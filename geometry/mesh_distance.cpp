#include <jelly/geometry/detail/mesh_distance.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace jelly {

namespace {

constexpr int kLeafSize = 4;

Vec3 closest_on_segment(const Vec3& q, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const Real l2 = ab.squaredNorm();
  if (l2 == 0) return a;
  return a + std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) * ab;
}

}  // namespace

Vec3 MeshDistance::closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                       Feature* feature) {
  Feature dummy;
  Feature& f = feature != nullptr ? *feature : dummy;
  // Voronoi regions of the corners, then of the edges, else the face (barycentric va, vb, vc).
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    f = Feature::kVertexA;
    return a;
  }
  const Vec3 bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    f = Feature::kVertexB;
    return b;
  }
  const Vec3 cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    f = Feature::kVertexC;
    return c;
  }
  const Real vc = d1 * d4 - d3 * d2;
  const Real vb = d5 * d2 - d1 * d6;
  const Real va = d3 * d6 - d5 * d4;
  const Real sum = va + vb + vc;  // |ab x ac|^2
  if (!(sum > 1e-30 * ab.squaredNorm() * ac.squaredNorm())) {
    // No area: the nearest of the three edges.
    const Vec3 e[3] = {closest_on_segment(p, a, b), closest_on_segment(p, b, c),
                       closest_on_segment(p, c, a)};
    int best = 0;
    for (int k = 1; k < 3; ++k)
      if ((e[k] - p).squaredNorm() < (e[best] - p).squaredNorm()) best = k;
    f = best == 0 ? Feature::kEdgeAB : best == 1 ? Feature::kEdgeBC : Feature::kEdgeCA;
    return e[best];
  }
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    f = Feature::kEdgeAB;
    return a + d1 / (d1 - d3) * ab;
  }
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    f = Feature::kEdgeCA;
    return a + d2 / (d2 - d6) * ac;
  }
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    f = Feature::kEdgeBC;
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  f = Feature::kFace;
  return a + (vb / sum) * ab + (vc / sum) * ac;
}

MeshDistance::MeshDistance(TriangleMesh mesh) : mesh_(std::move(mesh)) {
  const int nt = mesh_.num_triangles();
  tris_.reserve(nt);
  face_normal_.resize(nt);
  edge_normal_.resize(nt);
  vertex_normal_.assign(mesh_.num_vertices(), Vec3::Zero());
  // Each undirected edge's two faces (a closed manifold mesh has exactly two).
  std::map<std::pair<int, int>, Vec3> edge_sum;
  for (int i = 0; i < nt; ++i) {
    const Triangle& t = mesh_.triangles[i];
    const Vec3 &a = mesh_.vertices[t[0]], &b = mesh_.vertices[t[1]], &c = mesh_.vertices[t[2]];
    tris_.push_back({a, b, c, i});
    const Vec3 n = (b - a).cross(c - a);
    const Vec3 unit = n.norm() > 0 ? Vec3(n.normalized()) : Vec3(Vec3::Zero());
    face_normal_[i] = unit;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = mesh_.vertices[t[k]];
      const Vec3 u = mesh_.vertices[t[(k + 1) % 3]] - p, v = mesh_.vertices[t[(k + 2) % 3]] - p;
      const Real angle = std::atan2(u.cross(v).norm(), u.dot(v));
      vertex_normal_[t[k]] += angle * unit;
      // (emplace: a default Eigen vector is not zeroed)
      edge_sum.emplace(std::minmax(t[k], t[(k + 1) % 3]), Vec3::Zero()).first->second += unit;
    }
  }
  for (int i = 0; i < nt; ++i) {
    const Triangle& t = mesh_.triangles[i];
    for (int k = 0; k < 3; ++k) edge_normal_[i][k] = edge_sum.at(std::minmax(t[k], t[(k + 1) % 3]));
  }
  if (!tris_.empty()) {
    nodes_.reserve(2 * tris_.size() / kLeafSize + 2);
    build(0, static_cast<int>(tris_.size()));
  }
  on_surface_ = 1e-12 * std::max<Real>(mesh_.bounds().diagonal().norm(), 1e-300);
}

// Splits [begin, end) at the median of the centroids along the longest axis of their box;
// returns the node's index.
int MeshDistance::build(int begin, int end) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin;
  node.end = end;
  Eigen::AlignedBox3d centroids;
  for (int i = begin; i < end; ++i) {
    const Tri& t = tris_[i];
    node.box.extend(t.a);
    node.box.extend(t.b);
    node.box.extend(t.c);
    centroids.extend((t.a + t.b + t.c) / 3);
  }
  if (end - begin > kLeafSize) {
    int axis;
    centroids.sizes().maxCoeff(&axis);
    const int mid = begin + (end - begin) / 2;
    std::nth_element(tris_.begin() + begin, tris_.begin() + mid, tris_.begin() + end,
                     [axis](const Tri& x, const Tri& y) {
                       return x.a[axis] + x.b[axis] + x.c[axis] < y.a[axis] + y.b[axis] + y.c[axis];
                     });
    node.left = build(begin, mid);
    node.right = build(mid, end);
  }
  nodes_[id] = node;
  return id;
}

Real MeshDistance::unsigned_distance(const Vec3& q, Vec3* closest, int* triangle, Feature* feature,
                                     int hint) const {
  // Depth-first, the nearer child first; a node whose box is no nearer than the best triangle
  // found so far is skipped. A hint's distance (a little more) bounds the search from the start:
  // it skips only nodes that hold no nearest triangle, and the nearest triangles are met in the
  // same order, so the answer (ties too) does not depend on the hint.
  Real best = std::numeric_limits<Real>::infinity();
  if (hint >= 0 && hint < mesh_.num_triangles()) {
    const Triangle& t = mesh_.triangles[hint];
    const Vec3 c =
        closest_on_triangle(q, mesh_.vertices[t[0]], mesh_.vertices[t[1]], mesh_.vertices[t[2]]);
    best = (c - q).squaredNorm() * (1 + 1e-9) + std::numeric_limits<Real>::min();
  }
  Vec3 best_point = Vec3::Zero();
  int best_triangle = -1;
  Feature best_feature = Feature::kFace;
  struct Entry {
    int node;
    Real bound;  // squared distance of q from the node's box
  };
  Entry stack[128];
  int top = 0;
  if (!nodes_.empty()) stack[top++] = {0, nodes_[0].box.squaredExteriorDistance(q)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.bound >= best) continue;
    const Node& n = nodes_[e.node];
    if (n.left < 0) {
      for (int i = n.begin; i < n.end; ++i) {
        const Tri& t = tris_[i];
        Feature f;
        const Vec3 c = closest_on_triangle(q, t.a, t.b, t.c, &f);
        const Real d2 = (c - q).squaredNorm();
        if (d2 < best) {
          best = d2;
          best_point = c;
          best_triangle = t.index;
          best_feature = f;
        }
      }
      continue;
    }
    const Real bl = nodes_[n.left].box.squaredExteriorDistance(q);
    const Real br = nodes_[n.right].box.squaredExteriorDistance(q);
    // The depth is at most log2(triangles / 4) + 1 (median splits), far below the stack's size.
    if (bl <= br) {
      if (br < best) stack[top++] = {n.right, br};
      if (bl < best) stack[top++] = {n.left, bl};
    } else {
      if (bl < best) stack[top++] = {n.left, bl};
      if (br < best) stack[top++] = {n.right, br};
    }
  }
  if (closest != nullptr) *closest = best_point;
  if (triangle != nullptr) *triangle = best_triangle;
  if (feature != nullptr) *feature = best_feature;
  return std::sqrt(best);
}

Vec3 MeshDistance::pseudo_normal(int triangle, Feature feature) const {
  const Triangle& t = mesh_.triangles[triangle];
  switch (feature) {
    case Feature::kFace:
      return face_normal_[triangle];
    case Feature::kVertexA:
      return vertex_normal_[t[0]];
    case Feature::kVertexB:
      return vertex_normal_[t[1]];
    case Feature::kVertexC:
      return vertex_normal_[t[2]];
    case Feature::kEdgeAB:
      return edge_normal_[triangle][0];
    case Feature::kEdgeBC:
      return edge_normal_[triangle][1];
    case Feature::kEdgeCA:
      return edge_normal_[triangle][2];
  }
  return face_normal_[triangle];
}

MeshDistance::Query MeshDistance::query(const Vec3& q, int hint) const {
  Query r;
  Feature feature = Feature::kFace;
  const Real d = unsigned_distance(q, &r.closest, &r.triangle, &feature, hint);
  if (r.triangle < 0) return r;
  // Inside when q lies behind the nearest feature's pseudo-normal (exact for a closed,
  // consistently oriented mesh that does not intersect itself).
  const Vec3 n = pseudo_normal(r.triangle, feature);
  const bool inside = (q - r.closest).dot(n) < 0;
  r.distance = inside ? -d : d;
  if (d > on_surface_) {
    r.normal = (q - r.closest) / r.distance;
  } else if (n.norm() > 0) {
    r.normal = n.normalized();
  }
  return r;
}

}  // namespace jelly
