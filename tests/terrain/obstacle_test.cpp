// Obstacles of simple shapes: exact signed distances and normals against the analytic shapes,
// their placement and motion, JSON round trips and bad input.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <random>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

#include "support/errors.hpp"

namespace jelly {
namespace {

using testing::error_of;

ObstacleSpec spec_of(ObstacleShape shape) {
  ObstacleSpec s;
  s.geometry.shape = shape;
  s.geometry.radius = 0.4;
  s.geometry.size = Vec3(1.0, 0.5, 2.0);
  s.geometry.height = 0.8;
  return s;
}

TEST(Obstacle, SphereDistanceAndNormal) {
  ObstacleSpec s = spec_of(ObstacleShape::kSphere);
  s.center = Vec3(1, 2, 3);
  const Obstacle o(s);
  EXPECT_NEAR(o.signed_distance(Vec3(1, 3, 3), 0), 0.6, 1e-15);
  EXPECT_NEAR(o.signed_distance(Vec3(1, 2, 3.1), 0), -0.3, 1e-15);
  EXPECT_TRUE(o.normal(Vec3(2, 2, 3), 0).isApprox(Vec3::UnitX()));
  EXPECT_TRUE(o.surface_velocity(Vec3(2, 2, 3), 0).isZero());
}

TEST(Obstacle, BoxDistanceFacesEdgesAndInside) {
  const Obstacle o(spec_of(ObstacleShape::kBox));  // half sizes 0.5, 0.25, 1
  EXPECT_NEAR(o.signed_distance(Vec3(0, 1, 0), 0), 0.75, 1e-15);
  EXPECT_TRUE(o.normal(Vec3(0, 1, 0), 0).isApprox(Vec3::UnitY()));
  // Beyond an edge: the distance to the edge, the normal pointing from it.
  EXPECT_NEAR(o.signed_distance(Vec3(0.8, 0.65, 0), 0), 0.5, 1e-15);
  EXPECT_TRUE(o.normal(Vec3(0.8, 0.65, 0), 0).isApprox(Vec3(0.6, 0.8, 0)));
  // Inside: minus the distance to the nearest face, normal out through it.
  EXPECT_NEAR(o.signed_distance(Vec3(0.1, -0.2, 0.5), 0), -0.05, 1e-15);
  EXPECT_TRUE(o.normal(Vec3(0.1, -0.2, 0.5), 0).isApprox(-Vec3::UnitY()));
}

TEST(Obstacle, CapsuleAndCylinder) {
  const Obstacle capsule(spec_of(ObstacleShape::kCapsule));  // r 0.4, caps at y = +-0.4
  EXPECT_NEAR(capsule.signed_distance(Vec3(1, 0.3, 0), 0), 0.6, 1e-15);
  EXPECT_NEAR(capsule.signed_distance(Vec3(0, 1.4, 0), 0), 0.6, 1e-15);
  EXPECT_TRUE(capsule.normal(Vec3(0, 1.4, 0), 0).isApprox(Vec3::UnitY()));
  const Obstacle cylinder(spec_of(ObstacleShape::kCylinder));  // r 0.4, y in [-0.4, 0.4]
  EXPECT_NEAR(cylinder.signed_distance(Vec3(0, 0, 1), 0), 0.6, 1e-15);
  EXPECT_NEAR(cylinder.signed_distance(Vec3(0.1, 1, 0), 0), 0.6, 1e-15);
  EXPECT_NEAR(cylinder.signed_distance(Vec3(0.7, 0.8, 0), 0), 0.5, 1e-15);  // rim
  EXPECT_TRUE(cylinder.normal(Vec3(0.7, 0.8, 0), 0).isApprox(Vec3(0.6, 0.8, 0)));
  EXPECT_NEAR(cylinder.signed_distance(Vec3(0.3, 0, 0), 0), -0.1, 1e-15);
}

// For every shape, turned and moved: the normal is the distance's gradient, and the point
// p - d(p) n(p) lies on the surface, at random points outside and inside.
TEST(Obstacle, NormalIsTheGradientAndClosestPointsLieOnTheSurface) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1.5, 1.5);
  for (ObstacleShape shape : {ObstacleShape::kSphere, ObstacleShape::kBox, ObstacleShape::kCapsule,
                              ObstacleShape::kCylinder}) {
    ObstacleSpec s = spec_of(shape);
    s.center = Vec3(0.3, -0.2, 0.1);
    s.rotation_degrees = Vec3(10, 20, 30);
    s.motion = Path::oscillation(Vec3(0.2, 0.1, 0), 0.5);
    s.angular_velocity_degrees = Vec3(0, 45, 10);
    const Obstacle o(s);
    const Real t = 0.7;
    int tested = 0;
    for (int k = 0; k < 2000; ++k) {
      const Vec3 p = o.position(t) + Vec3(u(rng), u(rng), u(rng));
      const Real d = o.signed_distance(p, t);
      const Vec3 n = o.normal(p, t);
      EXPECT_NEAR(n.norm(), 1.0, 1e-12);
      EXPECT_NEAR(o.signed_distance(p - d * n, t), 0.0, 1e-12) << obstacle_shape_name(shape);
      // Central differences, away from the ridges where the gradient jumps.
      const Real e = 1e-6;
      Vec3 g;
      for (int a = 0; a < 3; ++a) {
        Vec3 dp = Vec3::Zero();
        dp[a] = e;
        g[a] = (o.signed_distance(p + dp, t) - o.signed_distance(p - dp, t)) / (2 * e);
      }
      if (std::abs(g.norm() - 1) > 1e-6) continue;  // on a ridge
      EXPECT_LT((g - n).norm(), 1e-6) << obstacle_shape_name(shape) << " " << p.transpose();
      ++tested;
    }
    EXPECT_GT(tested, 1800) << obstacle_shape_name(shape);
  }
}

// The surface velocity is the rigid motion's at the closest point: translation plus spin.
TEST(Obstacle, SurfaceVelocityOfAMovingSpinningObstacle) {
  ObstacleSpec s = spec_of(ObstacleShape::kBox);
  s.motion = Path::keyframes({0, 10}, {Vec3::Zero(), Vec3(10, 0, 0)});
  s.angular_velocity_degrees = Vec3(0, 0, 90);
  const Obstacle o(s);
  const Real t = 1;  // centre at (1, 0, 0), turned 90 degrees about z
  EXPECT_TRUE(o.position(t).isApprox(Vec3(1, 0, 0)));
  // The top face (own +y) now faces -x; its half height 0.25 along world x.
  const Vec3 p = Vec3(1 - 0.25 - 0.1, 0, 0);
  EXPECT_NEAR(o.signed_distance(p, t), 0.1, 1e-12);
  EXPECT_TRUE(o.normal(p, t).isApprox(-Vec3::UnitX()));
  const Vec3 closest(1 - 0.25, 0, 0);
  const Vec3 expected = Vec3(1, 0, 0) + Vec3(0, 0, M_PI / 2).cross(closest - Vec3(1, 0, 0));
  EXPECT_LT((o.surface_velocity(p, t) - expected).norm(), 1e-12);
  // The pose carries the render mesh with it.
  const Eigen::Isometry3d pose = o.pose(t);
  EXPECT_TRUE((pose * Vec3(0, 0.25, 0)).isApprox(closest));
}

TEST(Obstacle, JsonRoundTripOfEveryShape) {
  for (const char* kind : {"sphere", "box", "capsule", "cylinder"}) {
    const Json j = Json::parse(R"({"center": [1, 2, 3], "radius": 0.3, "height": 0.5,
        "size": [1, 2, 3], "rotation_degrees": [0, 0, 15],
        "motion": {"kind": "oscillation", "amplitude": [0, 0.1, 0], "frequency": 2},
        "angular_velocity_degrees": [0, 30, 0]})");
    Json input = j;
    if (std::string(kind) == "sphere") input.erase("height"), input.erase("size");
    if (std::string(kind) == "box") input.erase("height"), input.erase("radius");
    if (std::string(kind) == "capsule" || std::string(kind) == "cylinder") input.erase("size");
    JsonFields f(input, "terrains[0]");
    const auto spec = find_terrain_kind(kind, "terrains[0].kind").read(f);
    f.reject_unknown();
    EXPECT_EQ(spec->kind(), kind);
    Json written;
    spec->write(written);
    JsonFields again(written, "terrains[0]");
    const auto back = find_terrain_kind(kind, "terrains[0].kind").read(again);
    Json rewritten;
    back->write(rewritten);
    EXPECT_EQ(written, rewritten) << kind;
    EXPECT_EQ(written["center"], input["center"]);
    const auto terrain = back->make();
    EXPECT_EQ(terrain->kind(), kind);
    EXPECT_FALSE(terrain->render_mesh().triangles.empty());
  }
}

TEST(Obstacle, BadInputNamesTheField) {
  const auto read = [](const char* kind, const char* text) {
    return error_of([&] {
      const Json j = Json::parse(text);
      JsonFields f(j, "terrains[1]");
      find_terrain_kind(kind, "terrains[1].kind").read(f);
    });
  };
  EXPECT_EQ(read("sphere", R"({"radius": 0})"),
            "terrains[1].radius = 0 is invalid: a finite radius > 0 (m)");
  EXPECT_EQ(read("sphere", R"({"radius": -1})"),
            "terrains[1].radius = -1 is invalid: a finite radius > 0 (m)");
  EXPECT_NE(read("sphere", R"({})").find("terrains[1].radius"), std::string::npos);
  EXPECT_EQ(read("box", R"({"size": [1, 0, 1]})"),
            "terrains[1].size = 1 0 1 is invalid: three finite edge lengths > 0 (m)");
  EXPECT_EQ(read("cylinder", R"({"radius": 1, "height": -2})"),
            "terrains[1].height = -2 is invalid: a finite length > 0 (m)");
  ObstacleSpec s = spec_of(ObstacleShape::kSphere);
  s.center = Vec3(0, std::numeric_limits<Real>::quiet_NaN(), 0);
  const std::string nan_centre = error_of([&] { s.validate("terrains[2]."); });
  EXPECT_EQ(nan_centre.rfind("terrains[2].center = ", 0), 0u) << nan_centre;
  EXPECT_NE(nan_centre.find("nan"), std::string::npos) << nan_centre;
  EXPECT_NE(nan_centre.find("is invalid: finite coordinates"), std::string::npos) << nan_centre;
  EXPECT_NE(error_of([&] { Obstacle{s}; }).find("obstacle.center"), std::string::npos);
}

// A spin near a double's range overflowed omega's norm to inf and every particle to NaN.
TEST(Obstacle, AnAngularVelocityBeyondAnyPhysicalSpinIsRefused) {
  ObstacleSpec s = spec_of(ObstacleShape::kSphere);
  s.angular_velocity_degrees = Vec3(0, 1e300, 1e300);
  const std::string message = error_of([&] { s.validate("terrains[2]."); });
  EXPECT_EQ(message.rfind("terrains[2].angular_velocity_degrees = ", 0), 0u) << message;
  EXPECT_NE(message.find("e+300 is invalid: finite rates (degrees per second) whose norm is at "
                         "most 1e6 (about 2,800 turns a second)"),
            std::string::npos)
      << message;
  s.angular_velocity_degrees = Vec3(0, 2e6, 0);
  EXPECT_NE(error_of([&] { s.validate("terrains[2]."); }).find("angular_velocity_degrees"),
            std::string::npos);
  s.angular_velocity_degrees = Vec3(0, 36000, 0);
  s.validate("terrains[2].");
  const Obstacle spinning(s);
  EXPECT_TRUE(spinning.surface_velocity(Vec3(0, 0, 2), 1).allFinite());
}

}  // namespace
}  // namespace jelly
