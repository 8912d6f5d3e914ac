#pragma once
// The seed report's contact rules (sections 1.2 and 1.3), shared by the seed and seed_framework
// models: the collision test and the velocity reflection.
#include <cmath>

#include <jelly/terrain/terrain.hpp>

namespace jelly::seed_rules {

// Within epsilon of the surface (offset by the particle's `gap`, its body's thickness) and
// moving towards it (relative velocity). Gives the surface's normal and velocity.
inline bool touches(const Terrain& terrain, const ContactParams& c, Real t, Real gap, const Vec3& x,
                    const Vec3& v, Vec3& n, Vec3& u) {
  if (terrain.signed_distance(x, t) - gap >= c.epsilon || !terrain.can_contact(x, t)) return false;
  n = terrain.normal(x, t);
  u = terrain.surface_velocity(x, t);
  return (v - u).dot(n) < 0;
}

// Within epsilon and approaching, the normal velocity u1 becomes
// (m1 u1 + m2 u2 + m2 e (u2 - u1)) / (m1 + m2), u2 the surface's; a fixed plane (m2 infinite)
// gives u2 + e (u2 - u1) = -e u1. The tangential velocity is kept.
inline bool reflect(const Terrain& terrain, const ContactParams& c, Real m1, Real t, Real gap,
                    Eigen::Ref<const Vec3> x, Eigen::Ref<Vec3> v, Vec3& normal) {
  Vec3 n, u;
  if (!touches(terrain, c, t, gap, x, v, n, u)) return false;
  const Real u1 = v.dot(n);
  const Real u2 = u.dot(n);
  const Real m2 = terrain.mass();
  const Real e = c.restitution;
  const Real u1_new =
      std::isinf(m2) ? u2 + e * (u2 - u1) : (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2);
  v += (u1_new - u1) * n;
  normal = n;
  return true;
}

}  // namespace jelly::seed_rules
