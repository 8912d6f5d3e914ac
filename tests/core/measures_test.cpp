#include <gtest/gtest.h>

#include <jelly/geometry/cube.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

TEST(Measures, TwoParticleValues) {
  testing::TwoParticleSpring sys;
  sys.m = 2;
  sys.ks = 50;
  Model m = sys.model();
  m.gravity = Vec3(0, -10, 0);
  State s = sys.initial();
  s.v.segment<3>(0) = Vec3(1, 0, 0);
  s.v.segment<3>(3) = Vec3(0, 2, 0);
  EXPECT_DOUBLE_EQ(kinetic_energy(m, s), 0.5 * 2 * 1 + 0.5 * 2 * 4);
  EXPECT_NEAR(elastic_energy(m, s), 0.5 * 50 * 0.1 * 0.1, 1e-14);
  EXPECT_NEAR(gravitational_energy(m, s), 0.0, 1e-14);  // both at y = 0
  EXPECT_TRUE(linear_momentum(m, s).isApprox(Vec3(2, 4, 0)));
  const Vec3 com = center_of_mass(m, s);
  EXPECT_NEAR(com.x(), 0.5, 1e-14);
  // L = sum m x cross v: only particle 1 (x = 1.05, v = (0, 2, 0)) contributes.
  EXPECT_TRUE(angular_momentum(m, s).isApprox(Vec3(0, 0, 2 * 1.05 * 2)));
}

TEST(Model, ValidateNamesTheSpring) {
  testing::TwoParticleSpring sys;
  Model m = sys.model();
  m.springs.ks[0] = -3;
  try {
    m.validate();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "springs[0].ks = -3 is invalid: a finite stiffness >= 0");
  }
}

}  // namespace
}  // namespace jelly
