#include <jelly/viewer/framing.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <jelly/viewer/detail/ray_triangle.hpp>
#include <jelly/viewer/scene_adapter.hpp>

namespace jelly::viewer {

namespace {

using Vec3f = Eigen::Vector3f;

// The triangles of the terrains that can stand between the camera and the bodies (all but the
// ground planes), in the world at one time, with their bounds.
struct Occluders {
  std::vector<std::array<Vec3f, 3>> triangles;
  Eigen::AlignedBox3f box;

  Occluders(const Terrains& terrains, Real t) {
    for (const auto& terrain : terrains) {
      if (is_ground(*terrain)) continue;
      const TriangleMesh mesh = terrain->render_mesh();
      const Eigen::Isometry3d pose = terrain->pose(t);
      for (const Triangle& tri : mesh.triangles) {
        std::array<Vec3f, 3> world;
        for (int i = 0; i < 3; ++i) {
          world[static_cast<size_t>(i)] =
              (pose * mesh.vertices[static_cast<size_t>(tri[static_cast<size_t>(i)])])
                  .cast<float>();
          box.extend(world[static_cast<size_t>(i)]);
        }
        triangles.push_back(world);
      }
    }
  }

  bool empty() const { return triangles.empty(); }

  // The nearest hit of the ray o + s d (d a unit vector) with 0 < s < reach, or reach.
  float first_hit(const Vec3f& o, const Vec3f& d, float reach) const {
    // Slab test against the bounds first: most sight lines pass far from the obstacles.
    float s0 = 0, s1 = reach;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(d[a]) < 1e-12f) {
        if (o[a] < box.min()[a] || o[a] > box.max()[a]) return reach;
        continue;
      }
      float near = (box.min()[a] - o[a]) / d[a], far = (box.max()[a] - o[a]) / d[a];
      if (near > far) std::swap(near, far);
      s0 = std::max(s0, near);
      s1 = std::min(s1, far);
      if (s0 > s1) return reach;
    }
    float best = reach;
    for (const auto& tri : triangles) {
      const float s = detail::ray_triangle(o, d, tri[0], tri[1], tri[2]);
      if (s > 0 && s < best) best = s;
    }
    return best;
  }
};

// The highest ground plane (a terrain whose surface faces up) straight below p, or -infinity.
Real ground_below(const Vec3& p, const Terrains& terrains, Real t) {
  Real ground = -std::numeric_limits<Real>::infinity();
  for (const auto& terrain : terrains) {
    if (!is_ground(*terrain)) continue;
    const Vec3 n = terrain->normal(p, t);
    if (n.y() < 0.1) continue;
    const Real y = p.y() - terrain->signed_distance(p, t) / n.y();
    const Vec3 foot(p.x(), y, p.z());
    if (y <= p.y() && terrain->can_contact(foot, t)) ground = std::max(ground, y);
  }
  return ground;
}

}  // namespace

void add_sight_points(const VecX& x, const Terrains& terrains, Real t, int count,
                      std::vector<Vec3f>& out) {
  const Eigen::Index n = x.size() / 3;
  if (n == 0 || count <= 0) return;
  const Occluders occluders(terrains, t);
  const Eigen::Index step = std::max<Eigen::Index>(1, n / count);
  for (Eigen::Index i = step / 2; i < n; i += step) {
    const Vec3 p = x.segment<3>(3 * i);
    out.push_back(p.cast<float>());
    Real landing = ground_below(p, terrains, t);
    if (!occluders.empty()) {
      const float reach = 1e4f;
      const float s = occluders.first_hit(p.cast<float>(), -Vec3f::UnitY(), reach);
      if (s < reach) landing = std::max(landing, p.y() - static_cast<Real>(s));
    }
    // A little above the surface, so that the surface itself does not hide it.
    if (std::isfinite(landing))
      out.push_back(Vec3f(static_cast<float>(p.x()), static_cast<float>(landing + 0.05),
                          static_cast<float>(p.z())));
  }
}

Camera framing_camera(const Vec3& lo, const Vec3& hi, const Terrains& terrains, Real t,
                      float aspect, const std::vector<Sight>& sights, bool with_ground) {
  Vec3 a = lo, b = hi;
  const Real ground = ground_below(0.5 * (lo + hi), terrains, t);
  Real below = ground;
  // Obstacles' surfaces below the centre count as ground too (the bottom of a bowl).
  const Occluders occluders(terrains, t);
  if (!occluders.empty()) {
    const Vec3 centre = 0.5 * (lo + hi);
    const float reach = 1e4f;
    const float s = occluders.first_hit(centre.cast<float>(), -Vec3f::UnitY(), reach);
    if (s < reach) below = std::max(below, centre.y() - static_cast<Real>(s));
  }
  if (with_ground && std::isfinite(below)) {
    a.y() = std::min(a.y(), below);
    b.y() = std::max(b.y(), below);
  }
  constexpr float kYaw = -20, kLowestPitch = 18;
  if (occluders.empty() || sights.empty())
    return frame_box(a.cast<float>(), b.cast<float>(), aspect, kYaw, kLowestPitch);
  size_t total = 0;
  for (const Sight& s : sights) total += s.points.size();
  Camera best;
  size_t best_hidden = std::numeric_limits<size_t>::max();
  for (float pitch = kLowestPitch; pitch < 80; pitch += 10) {
    const Camera camera = frame_box(a.cast<float>(), b.cast<float>(), aspect, kYaw, pitch);
    size_t hidden = 0;
    for (const Sight& s : sights) {
      const Vec3f eye = camera.eye() + s.shift;
      for (const Vec3f& p : s.points) {
        const Vec3f d = p - eye;
        const float length = d.norm();
        if (length < 1e-6f) continue;
        const float reach = length - 0.02f;
        if (occluders.first_hit(eye, d / length, reach) < reach) ++hidden;
      }
    }
    if (hidden < best_hidden) {
      best = camera;
      best_hidden = hidden;
    }
    if (20 * hidden <= total) break;
  }
  return best;
}

}  // namespace jelly::viewer
