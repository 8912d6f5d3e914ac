// The generalized winding number: 1 inside, 0 outside, the fast tree against the direct sum.
#include <random>

#include <gtest/gtest.h>

#include <jelly/geometry/detail/winding_number.hpp>

namespace jelly {
namespace {

TEST(WindingNumber, OneInsideZeroOutsideOfAClosedMesh) {
  const TriangleMesh sphere = sphere_mesh(1, 24, 48);
  const WindingNumber w(sphere);
  EXPECT_NEAR(w.exact(Vec3::Zero()), 1, 1e-12);
  EXPECT_NEAR(w.exact(Vec3(0.3, -0.5, 0.2)), 1, 1e-12);
  EXPECT_NEAR(w.exact(Vec3(1.5, 0, 0)), 0, 1e-12);
  EXPECT_NEAR(w.exact(Vec3(0, 9, 0)), 0, 1e-12);
  EXPECT_NEAR(w(Vec3::Zero()), 1, 5e-3);
  EXPECT_NEAR(w(Vec3(0, 9, 0)), 0, 1e-6);
}

TEST(WindingNumber, TreeAgreesWithTheDirectSum) {
  TriangleMesh mesh = sphere_mesh(1, 40, 80);
  TriangleMesh capsule = capsule_mesh(0.4, 1.5, 10, 40);
  for (Vec3& v : capsule.vertices) v += Vec3(0.8, 0.2, 0);
  mesh.append(capsule);  // two overlapping closed parts: 2 where both hold the point
  const WindingNumber w(mesh);
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-2, 2);
  Real worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 q(u(rng), u(rng), u(rng));
    worst = std::max(worst, std::abs(w(q) - w.exact(q)));
  }
  EXPECT_LT(worst, 1e-2);  // far below the 1/2 that separates inside from outside
  EXPECT_NEAR(w(Vec3(0.8, 0.2, 0)), 2, 1e-2);
  EXPECT_NEAR(w(Vec3(-0.5, 0, 0)), 1, 1e-2);
  // Farther than beta = 2 radii from the root cluster, the expansion alone: tiny error.
  EXPECT_NEAR(w(Vec3(9, 7, -8)), w.exact(Vec3(9, 7, -8)), 1e-6);
}

TEST(WindingNumber, ASmallHoleChangesLittle) {
  TriangleMesh sphere = sphere_mesh(1, 24, 48);
  sphere.triangles.erase(sphere.triangles.begin() + 500, sphere.triangles.begin() + 504);
  const WindingNumber w(sphere);
  EXPECT_GT(w(Vec3::Zero()), 0.99);
  EXPECT_LT(w(Vec3(0, 3, 0)), 0.01);
}

TEST(WindingNumber, NearSurface) {
  const WindingNumber w(box_mesh(Vec3(2, 2, 2)));
  EXPECT_TRUE(w.near_surface(Vec3(1, 0.3, 0.2), 1e-12));
  EXPECT_TRUE(w.near_surface(Vec3(1, 1, 1), 1e-12));
  EXPECT_TRUE(w.near_surface(Vec3(1.05, 0, 0), 0.06));
  EXPECT_FALSE(w.near_surface(Vec3(1.05, 0, 0), 0.04));
  EXPECT_FALSE(w.near_surface(Vec3(0, 0, 0), 0.9));
  EXPECT_NEAR(w.exact(Vec3(1, 1, 1)), 0.125, 1e-12);  // a corner: an eighth of the sphere
}

}  // namespace
}  // namespace jelly
