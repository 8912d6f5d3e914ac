#include <jelly/geometry/detail/winding_number.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace jelly {

namespace {

constexpr int kLeafSize = 8;
constexpr Real kFourPi = 4 * M_PI;

}  // namespace

WindingNumber::WindingNumber(const TriangleMesh& mesh, Real accuracy) : accuracy_(accuracy) {
  triangles_.reserve(mesh.triangles.size());
  std::vector<Vec3> centroids;
  centroids.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const Tri tri{mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
    triangles_.push_back(tri);
    centroids.push_back((tri.a + tri.b + tri.c) / 3);
  }
  if (triangles_.empty()) return;
  std::vector<int> order(triangles_.size());
  std::iota(order.begin(), order.end(), 0);
  nodes_.reserve(2 * triangles_.size() / kLeafSize + 2);
  build(0, static_cast<int>(triangles_.size()), order, centroids);
  // The leaves' triangles side by side, in the order the tree holds them.
  std::vector<Tri> sorted(triangles_.size());
  for (std::size_t i = 0; i < order.size(); ++i) sorted[i] = triangles_[order[i]];
  triangles_ = std::move(sorted);
}

// Splits [begin, end) of `order` at the median of the centroids along the longest axis of their
// box, builds both halves, and sums their expansions about the node's own centre (a leaf sums
// its triangles'); returns the node's index.
int WindingNumber::build(int begin, int end, std::vector<int>& order,
                         const std::vector<Vec3>& centroids) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin;
  node.end = end;
  node.area_normal.setZero();
  node.first_moment.setZero();
  for (Eigen::Matrix3d& m : node.second_moment) m.setZero();
  if (end - begin <= kLeafSize) {
    Real area_sum = 0;
    Vec3 weighted = Vec3::Zero();
    for (int i = begin; i < end; ++i) {
      const Tri& t = triangles_[order[i]];
      node.box.extend(t.a);
      node.box.extend(t.b);
      node.box.extend(t.c);
      const Real area = 0.5 * (t.b - t.a).cross(t.c - t.a).norm();
      area_sum += area;
      weighted += area * centroids[order[i]];
    }
    node.centre = area_sum > 0 ? Vec3(weighted / area_sum) : Vec3(node.box.center());
    node.area = area_sum;
    for (int i = begin; i < end; ++i) {
      const Tri& t = triangles_[order[i]];
      // area x unit normal = half the cross product.
      const Vec3 an = 0.5 * (t.b - t.a).cross(t.c - t.a);
      node.area_normal += an;
      node.first_moment += (centroids[order[i]] - node.centre) * an.transpose();
      // E[d d^T] over a triangle with corners e_i = v_i - centre: (sum e_i e_i^T + s s^T) / 12,
      // s = sum e_i.
      const Vec3 ea = t.a - node.centre, eb = t.b - node.centre, ec = t.c - node.centre;
      const Vec3 sum = ea + eb + ec;
      const Eigen::Matrix3d spread = (ea * ea.transpose() + eb * eb.transpose() +
                                      ec * ec.transpose() + sum * sum.transpose()) /
                                     12;
      for (int k = 0; k < 3; ++k) node.second_moment[k] += an[k] * spread;
      for (const Vec3* v : {&t.a, &t.b, &t.c}) {
        node.radius = std::max(node.radius, (*v - node.centre).norm());
      }
    }
    nodes_[id] = node;
    return id;
  }
  Eigen::AlignedBox3d centre_box;
  for (int i = begin; i < end; ++i) centre_box.extend(centroids[order[i]]);
  int axis;
  centre_box.diagonal().maxCoeff(&axis);
  const int mid = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](int x, int y) { return centroids[x][axis] < centroids[y][axis]; });
  node.left = build(begin, mid, order, centroids);
  node.right = build(mid, end, order, centroids);
  const Node& l = nodes_[node.left];
  const Node& r = nodes_[node.right];
  node.box = l.box.merged(r.box);
  node.area = l.area + r.area;
  node.centre = node.area > 0 ? Vec3((l.area * l.centre + r.area * r.centre) / node.area)
                              : Vec3(node.box.center());
  // A child's moments about the node's centre c from those about its own c_i, with
  // delta = c_i - c (each d = x - c_i becomes d + delta):
  //   M' = M + delta N^T,  C'_k = C_k + m_k delta^T + delta m_k^T + N_k delta delta^T
  // (m_k the k-th column of M); the radius is bounded by |delta| + r_i.
  for (const Node* child : {&l, &r}) {
    const Vec3 delta = child->centre - node.centre;
    node.area_normal += child->area_normal;
    node.first_moment += child->first_moment + delta * child->area_normal.transpose();
    for (int k = 0; k < 3; ++k) {
      const Vec3 m = child->first_moment.col(k);
      node.second_moment[k] += child->second_moment[k] + m * delta.transpose() +
                               delta * m.transpose() +
                               child->area_normal[k] * delta * delta.transpose();
    }
    node.radius = std::max(node.radius, delta.norm() + child->radius);
  }
  nodes_[id] = node;
  return id;
}

// Van Oosterom and Strackee (1983): tan(omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c| +
// (b.c)|a| + (c.a)|b|), with a, b, c the corners relative to q. Positive when the triangle is
// counter-clockwise seen from the side away from q.
Real WindingNumber::solid_angle(const Tri& t, const Vec3& q) {
  const Vec3 a = t.a - q, b = t.b - q, c = t.c - q;
  const Real la = a.norm(), lb = b.norm(), lc = c.norm();
  const Real numerator = a.dot(b.cross(c));
  const Real denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return 2 * std::atan2(numerator, denominator);
}

Real WindingNumber::operator()(const Vec3& q) const {
  if (nodes_.empty()) return 0;
  Real omega = 0;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    const Vec3 r = n.centre - q;
    const Real d2 = r.squaredNorm();
    if (d2 > accuracy_ * accuracy_ * n.radius * n.radius) {
      // The cluster's solid angle, integral of normal . (x - q) / |x - q|^3 over its area,
      // expanded about its centre to second order in d = x - centre: with F(r) = r / |r|^3,
      //   dF_k/dr_i = delta_ki / |r|^3 - 3 r_k r_i / |r|^5,
      //   d2F_k/dr_i dr_j = -3 (delta_ki r_j + delta_kj r_i + delta_ij r_k) / |r|^5
      //                     + 15 r_k r_i r_j / |r|^7,
      // omega ~ N . F + sum_ki M_ik dF_k/dr_i + 1/2 sum_kij C_kij d2F_k/dr_i dr_j, with N the
      // summed area normals, M the first and C the second moment above.
      const Real d = std::sqrt(d2);
      const Real inv3 = 1 / (d2 * d);
      const Real inv5 = inv3 / d2;
      const Real inv7 = inv5 / d2;
      const Vec3 mr = n.first_moment * r;
      Real c_iij_rj = 0, rk_trace = 0, c_rrr = 0;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Matrix3d& c = n.second_moment[k];
        c_iij_rj += c.row(k).dot(r);
        rk_trace += r[k] * c.trace();
        c_rrr += r[k] * r.dot(c * r);
      }
      omega += n.area_normal.dot(r) * inv3 + n.first_moment.trace() * inv3 - 3 * r.dot(mr) * inv5 -
               1.5 * (2 * c_iij_rj + rk_trace) * inv5 + 7.5 * c_rrr * inv7;
    } else if (n.left < 0) {
      for (int i = n.begin; i < n.end; ++i) omega += solid_angle(triangles_[i], q);
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return omega / kFourPi;
}

Real WindingNumber::exact(const Vec3& q) const {
  Real omega = 0;
  for (const Tri& t : triangles_) omega += solid_angle(t, q);
  return omega / kFourPi;
}

// Ericson, Real-Time Collision Detection, 5.1.5: the closest point of a triangle by regions.
Real WindingNumber::squared_distance(const Tri& t, const Vec3& p) {
  const Vec3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();
  const Vec3 bp = p - t.b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Real v = d1 / (d1 - d3);
    return (ap - v * ab).squaredNorm();
  }
  const Vec3 cp = p - t.c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Real w = d2 / (d2 - d6);
    return (ap - w * ac).squaredNorm();
  }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (bp - w * (t.c - t.b)).squaredNorm();
  }
  const Real denom = 1 / (va + vb + vc);
  const Real v = vb * denom, w = vc * denom;
  return (ap - ab * v - ac * w).squaredNorm();
}

bool WindingNumber::near_surface(const Vec3& q, Real distance) const {
  if (nodes_.empty()) return false;
  const Real d2 = distance * distance;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (n.box.squaredExteriorDistance(q) > d2) continue;
    if (n.left < 0) {
      for (int i = n.begin; i < n.end; ++i) {
        if (squared_distance(triangles_[i], q) <= d2) return true;
      }
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return false;
}

}  // namespace jelly
