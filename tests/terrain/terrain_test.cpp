#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {
namespace {

TEST(ElevatorMotion, SeedCycleIsAnalytic) {
  const ElevatorMotion m = ElevatorMotion::seed();
  EXPECT_DOUBLE_EQ(m.period(), 4);
  // Up: offset 1.5 t^2, velocity 3 t.
  EXPECT_NEAR(m.offset(1.0), 1.5, 1e-12);
  EXPECT_NEAR(m.velocity(1.0), 3.0, 1e-12);
  EXPECT_NEAR(m.acceleration(1.0), 3.0, 1e-12);
  // Dead stop at t = 2, then down from offset 6 with velocity -3 (t - 2).
  EXPECT_NEAR(m.offset(2.0), 6.0, 1e-12);
  EXPECT_NEAR(m.velocity(2.0), 0.0, 1e-12);
  EXPECT_NEAR(m.offset(3.0), 6.0 - 1.5, 1e-12);
  EXPECT_NEAR(m.velocity(3.0), -3.0, 1e-12);
  // Back at the start after a cycle, and periodic.
  EXPECT_NEAR(m.offset(4.0), 0.0, 1e-12);
  EXPECT_NEAR(m.offset(5.5), m.offset(1.5), 1e-12);
  EXPECT_NEAR(m.velocity(9.5), m.velocity(1.5), 1e-12);
}

TEST(ElevatorMotion, RejectsCycleNotEndingAtRest) {
  EXPECT_THROW(ElevatorMotion({{1, 2, false}}), InputError);
  EXPECT_THROW(ElevatorMotion({{0, 2, true}}), InputError);
  // Accelerate then decelerate without stops: ends at rest, repeats, rises 1 m per cycle.
  const ElevatorMotion m({{1, 1, false}, {1, -1, false}});
  EXPECT_NEAR(m.offset(2), 1.0, 1e-12);
  EXPECT_NEAR(m.offset(4), 2.0, 1e-12);
}

TEST(Elevator, FootprintAndSurface) {
  const Elevator e;
  EXPECT_NEAR(e.height(0), 1.0, 1e-12);
  EXPECT_NEAR(e.height(2.0), 7.0, 1e-12);
  EXPECT_TRUE(e.can_contact(Vec3(2.4, 1.0, -2.4), 0));
  EXPECT_FALSE(e.can_contact(Vec3(2.6, 1.0, 0), 0));
  EXPECT_FALSE(e.can_contact(Vec3(0, -0.5, 0), 0));  // deeper than the thickness
  EXPECT_NEAR(e.signed_distance(Vec3(0, 3, 0), 1.0), 3 - 2.5, 1e-12);
  EXPECT_NEAR(e.surface_velocity(Vec3::Zero(), 1.0).y(), 3.0, 1e-12);
  EXPECT_EQ(e.mass(), 1);
}

TEST(Plane, SeedSlope) {
  const Plane p = Plane::slope(20);
  const Real a = 20 * M_PI / 180;
  EXPECT_TRUE(p.unit_normal().isApprox(Vec3(std::sin(a), std::cos(a), 0)));
  EXPECT_NEAR(p.signed_distance(Vec3(0, 1, 0), 0), std::cos(a), 1e-15);
}

TEST(Plane, BadInput) {
  try {
    Plane(Vec3::Zero(), Vec3::Zero());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plane.normal = 0 0 0 is invalid"), std::string::npos)
        << e.what();
  }
  ContactParams c;
  c.restitution = 1.5;
  EXPECT_THROW(Plane(Vec3::Zero(), Vec3::UnitY(), c), InputError);
  c = ContactParams{};
  c.static_friction = 0.1;  // below kinetic friction 0.5
  EXPECT_THROW(Plane(Vec3::Zero(), Vec3::UnitY(), c), InputError);
  EXPECT_THROW(contact_model_from_name("bouncy", "terrains[0].contact"), InputError);
}

// A terrain built from its spec alone answers with the spec's contact model, as the same spec
// made by its registry (spec.make()) does.
TEST(TerrainSpecContact, ConstructorsTakeTheSpecsOwnContact) {
  ContactParams contact;
  contact.model = ContactModel::kSeed;
  contact.restitution = 0.3;
  contact.friction = 0.2;
  ObstacleSpec sphere;
  sphere.geometry.shape = ObstacleShape::kSphere;
  sphere.geometry.radius = 0.5;
  sphere.contact = contact;
  ElevatorSpec platform;
  platform.contact = contact;
  const Obstacle obstacle(sphere);
  const Elevator elevator(platform);
  const std::unique_ptr<Terrain> made = sphere.make();
  for (const Terrain* t :
       {static_cast<const Terrain*>(&obstacle), static_cast<const Terrain*>(&elevator),
        static_cast<const Terrain*>(made.get())}) {
    EXPECT_EQ(t->contact().model, ContactModel::kSeed);
    EXPECT_DOUBLE_EQ(t->contact().restitution, 0.3);
    EXPECT_DOUBLE_EQ(t->contact().friction, 0.2);
  }
  // An explicit contact model still wins over the spec's.
  const Obstacle other(sphere, ContactParams{});
  EXPECT_EQ(other.contact().model, ContactModel::kCoulomb);
}

}  // namespace
}  // namespace jelly
