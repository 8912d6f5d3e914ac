#pragma once
// Closed meshes with known shapes for the mesh obstacle's tests (a bowl made by turning a
// profile about the y axis), and a temporary folder to write them to.
#include <cmath>
#include <string>
#include <vector>

#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/triangle_mesh.hpp>

#include "support/temp_dir.hpp"

namespace jelly::testing {

// A temporary directory to write meshes to.
class MeshDir : public TempDir {
 public:
  // Writes `mesh` under `name` and returns the path.
  std::string write(const std::string& name, const TriangleMesh& mesh) const {
    write_mesh(file(name), mesh);
    return file(name);
  }
};

// The surface swept by turning a profile (r, y) about the y axis in `segments` steps. The
// profile starts and ends on the axis (r = 0), which become two poles: the mesh is closed.
// Consistently oriented (outwards or inwards by the profile's direction: the mesh obstacle turns
// an inward mesh outwards).
inline TriangleMesh lathe_mesh(const std::vector<Eigen::Vector2d>& profile, int segments) {
  TriangleMesh m;
  const int n = static_cast<int>(profile.size());
  // Poles: profile[0] and profile[n - 1]; rings: profile[1 .. n - 2].
  m.vertices.push_back(Vec3(0, profile[0].y(), 0));
  for (int k = 1; k < n - 1; ++k) {
    for (int s = 0; s < segments; ++s) {
      const Real phi = 2 * M_PI * s / segments;
      m.vertices.push_back(
          Vec3(profile[k].x() * std::cos(phi), profile[k].y(), profile[k].x() * std::sin(phi)));
    }
  }
  m.vertices.push_back(Vec3(0, profile[n - 1].y(), 0));
  const int last = m.num_vertices() - 1;
  const auto ring = [segments](int k, int s) { return 1 + (k - 1) * segments + s % segments; };
  for (int s = 0; s < segments; ++s) {
    m.triangles.push_back({0, ring(1, s + 1), ring(1, s)});
    for (int k = 1; k < n - 2; ++k) {
      m.add_quad(ring(k, s), ring(k, s + 1), ring(k + 1, s + 1), ring(k + 1, s));
    }
    m.triangles.push_back({last, ring(n - 2, s), ring(n - 2, s + 1)});
  }
  return m;
}

// A hemispherical bowl open upwards: inner radius `radius` (the inside surface is the lower
// half of the sphere of that radius about the origin), wall `thickness`, rim at y = 0.
inline TriangleMesh bowl_mesh(Real radius, Real thickness, int rings = 24, int segments = 48) {
  std::vector<Eigen::Vector2d> profile;
  // Inner surface from the bottom up to the rim, across the rim, outer surface down.
  for (int i = 0; i <= rings; ++i) {
    const Real a = 0.5 * M_PI * i / rings;  // from the bottom
    profile.emplace_back(radius * std::sin(a), -radius * std::cos(a));
  }
  const Real outer = radius + thickness;
  for (int i = rings; i >= 0; --i) {
    const Real a = 0.5 * M_PI * i / rings;
    profile.emplace_back(outer * std::sin(a), -outer * std::cos(a));
  }
  return lathe_mesh(profile, segments);
}

}  // namespace jelly::testing
