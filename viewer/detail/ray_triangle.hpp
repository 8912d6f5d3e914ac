#pragma once
// Möller-Trumbore ray-triangle intersection, shared by picking (window.cpp) and the framing's
// sight lines (framing.cpp).
#include <cmath>

#include <Eigen/Geometry>

namespace jelly::viewer::detail {

// The ray parameter s of the hit of o + s d with triangle (a, b, c), or a negative value.
inline float ray_triangle(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                          const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                          const Eigen::Vector3f& c) {
  const Eigen::Vector3f e1 = b - a, e2 = c - a;
  const Eigen::Vector3f p = d.cross(e2);
  const float det = e1.dot(p);
  if (std::abs(det) < 1e-12f) return -1;
  const float inv = 1.0f / det;
  const Eigen::Vector3f s = o - a;
  const float u = s.dot(p) * inv;
  if (u < 0 || u > 1) return -1;
  const Eigen::Vector3f q = s.cross(e1);
  const float v = d.dot(q) * inv;
  if (v < 0 || u + v > 1) return -1;
  return e2.dot(q) * inv;
}

}  // namespace jelly::viewer::detail
