// The mesh obstacle's signed distance: the tree's nearest point against a search over every
// triangle, distance, normal and closest point against the analytic box and sphere, and the
// sign against the winding number.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <jelly/geometry/detail/mesh_distance.hpp>
#include <jelly/geometry/detail/winding_number.hpp>

#include "support/meshes.hpp"

namespace jelly {
namespace {

// Exact signed distance of an axis-aligned box of edges `size` centred at the origin.
Real box_distance(const Vec3& q, const Vec3& size) {
  const Vec3 d = q.cwiseAbs() - 0.5 * size;
  return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}

Real brute_force_distance(const TriangleMesh& m, const Vec3& q) {
  Real best = std::numeric_limits<Real>::infinity();
  for (const Triangle& t : m.triangles) {
    const Vec3 c =
        MeshDistance::closest_on_triangle(q, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
    best = std::min(best, (c - q).norm());
  }
  return best;
}

TEST(MeshDistance, ClosestPointOnATriangleInEveryRegion) {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  const auto at = [&](const Vec3& q) { return MeshDistance::closest_on_triangle(q, a, b, c); };
  EXPECT_LT((at(Vec3(0.5, 0.5, 3)) - Vec3(0.5, 0.5, 0)).norm(), 1e-15);  // face
  EXPECT_LT((at(Vec3(-1, -1, 1)) - a).norm(), 1e-15);                    // corners
  EXPECT_LT((at(Vec3(3, -1, 0)) - b).norm(), 1e-15);
  EXPECT_LT((at(Vec3(-1, 3, 0)) - c).norm(), 1e-15);
  EXPECT_LT((at(Vec3(1, -1, 1)) - Vec3(1, 0, 0)).norm(), 1e-15);  // edges
  EXPECT_LT((at(Vec3(-1, 1, -1)) - Vec3(0, 1, 0)).norm(), 1e-15);
  EXPECT_LT((at(Vec3(2, 2, 0)) - Vec3(1, 1, 0)).norm(), 1e-15);
  // No area: the nearest point of its edges.
  EXPECT_LT((MeshDistance::closest_on_triangle(Vec3(1, 1, 0), a, b, Vec3(1, 0, 0)) - Vec3(1, 0, 0))
                .norm(),
            1e-15);
}

// On a box mesh the distance, its sign, the normal and the nearest point are the analytic box's
// (to rounding), outside, inside, near faces, edges and corners.
TEST(MeshDistance, BoxMeshMatchesTheAnalyticBox) {
  const Vec3 size(1.0, 0.5, 2.0);
  const MeshDistance mesh(box_mesh(size));
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1.5, 1.5);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 q(u(rng), u(rng), u(rng));
    const MeshDistance::Query r = mesh.query(q);
    const Real exact = box_distance(q, size);
    ASSERT_NEAR(r.distance, exact, 1e-12) << q.transpose();
    // The nearest point is on the surface, |distance| away, along the normal.
    EXPECT_NEAR(box_distance(r.closest, size), 0.0, 1e-12);
    EXPECT_NEAR((q - r.closest).norm(), std::abs(r.distance), 1e-12);
    EXPECT_LT((q - r.distance * r.normal - r.closest).norm(), 1e-12);
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
    // The normal is the distance's gradient (central differences, away from the ridges inside
    // where the nearest face changes).
    const Vec3 d = q.cwiseAbs() - 0.5 * size;
    Vec3 sorted = d;
    std::sort(sorted.data(), sorted.data() + 3);
    if (exact < 0 && sorted[2] - sorted[1] < 1e-3) continue;
    const Real h = 1e-6;
    Vec3 g;
    for (int i = 0; i < 3; ++i) {
      const Vec3 e = h * Vec3::Unit(i);
      g[i] = (box_distance(q + e, size) - box_distance(q - e, size)) / (2 * h);
    }
    EXPECT_LT((r.normal - g).norm(), 1e-6) << q.transpose();
  }
  // On a face: the face's normal.
  const MeshDistance::Query top = mesh.query(Vec3(0.1, 0.25, 0.3));
  EXPECT_NEAR(top.distance, 0.0, 1e-15);
  EXPECT_LT((top.normal - Vec3::UnitY()).norm(), 1e-12);
}

// A sphere mesh is within its chord error of the sphere: |q| - r to that error, the normal the
// radial direction to the error's angle, and the tree gives the same distance as a search over
// every triangle.
TEST(MeshDistance, SphereMeshIsTheSphereToItsChordError) {
  const Real radius = 0.8;
  const TriangleMesh m = sphere_mesh(radius, 48, 96);
  const MeshDistance mesh(m);
  // Largest gap between the mesh and the sphere: a face's centre is at most r (1 - cos a) inside,
  // a the angle from the centre to its farthest corner (at most the diagonal of a cell: pi / 48
  // across latitudes and 2 pi / 96 across longitudes).
  const Real a = std::hypot(M_PI / 48, M_PI / 48) / 2;
  const Real chord = radius * (1 - std::cos(a));
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> u(-1.6, 1.6);
  int inside = 0;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 q(u(rng), u(rng), u(rng));
    const MeshDistance::Query r = mesh.query(q);
    ASSERT_NEAR(r.distance, q.norm() - radius, chord) << q.transpose();
    EXPECT_NEAR(r.closest.norm(), radius, chord);
    inside += r.distance < 0;
    EXPECT_NEAR(std::abs(r.distance), brute_force_distance(m, q), 1e-12);
    if (std::abs(q.norm() - radius) > 0.1) {
      // Away from the surface the normal turns from the radial direction by at most about
      // chord / distance.
      EXPECT_GT(r.normal.dot(q.normalized()), std::cos(2 * a + chord / 0.1)) << q.transpose();
    }
  }
  EXPECT_GT(inside, 50);  // the sample reached inside
}

// Far points are found as exactly as near ones.
TEST(MeshDistance, FarPoints) {
  const MeshDistance mesh(box_mesh(Vec3(1, 1, 1)));
  EXPECT_NEAR(mesh.query(Vec3(0, 100, 0)).distance, 99.5, 1e-12);
  EXPECT_NEAR(mesh.query(Vec3(100, 100, 100)).distance, std::sqrt(3.0) * 99.5, 1e-9);
  EXPECT_NEAR(mesh.query(Vec3(0, 0, 0)).distance, -0.5, 1e-15);
}

// The pseudo-normal sign agrees with the generalized winding number (summed exactly) on a
// concave mesh, near its surface (where the nearest feature is often an edge or a vertex) and
// away from it; and a hint changes nothing, not even which of equally near triangles is named.
TEST(MeshDistance, SignIsTheWindingNumbersAndHintsChangeNothing) {
  const TriangleMesh bowl = testing::bowl_mesh(1.0, 0.1, 12, 20);
  const MeshDistance mesh(bowl);
  const WindingNumber winding(bowl);
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-1.3, 1.3), v(-1e-3, 1e-3), pick(0, 1);
  int inside = 0;
  for (int k = 0; k < 3000; ++k) {
    Vec3 q(u(rng), u(rng), u(rng));
    if (k % 2 == 1) {  // near a vertex or an edge of the mesh
      const Triangle& t = bowl.triangles[k % bowl.num_triangles()];
      const Real s = pick(rng);
      q = (k % 4 == 1 ? bowl.vertices[t[0]]
                      : Vec3(s * bowl.vertices[t[0]] + (1 - s) * bowl.vertices[t[1]])) +
          Vec3(v(rng), v(rng), v(rng));
    }
    const MeshDistance::Query r = mesh.query(q);
    const bool in = winding.exact(q) >= 0.5;
    ASSERT_EQ(r.distance < 0, in) << q.transpose() << " d = " << r.distance;
    inside += in;
    const MeshDistance::Query h = mesh.query(q, (7 * k) % bowl.num_triangles());
    EXPECT_EQ(h.distance, r.distance);
    EXPECT_EQ(h.triangle, r.triangle);
    EXPECT_EQ(h.closest, r.closest);
  }
  EXPECT_GT(inside, 100);
}

}  // namespace
}  // namespace jelly
