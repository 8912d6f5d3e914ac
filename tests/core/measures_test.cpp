#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/core/model.hpp>
#include <jelly/geometry/cube.hpp>

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
  // Every field of a spring, and a particle's mass, is checked (the valid ones skip building
  // the names).
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const std::vector<std::pair<std::function<void(Model&)>, std::string>> bad = {
      {[](Model& b) { b.springs.a[0] = -1; }, "springs[0].a = -1"},
      {[](Model& b) { b.springs.a[0] = 2; }, "springs[0].a = 2"},
      {[](Model& b) { b.springs.b[0] = b.springs.a[0]; }, "springs[0].b = "},
      {[](Model& b) { b.springs.b[0] = 7; }, "springs[0].b = 7"},
      {[&](Model& b) { b.springs.rest_length[0] = nan; }, "springs[0].rest_length = nan"},
      {[](Model& b) { b.springs.rest_length[0] = 0; }, "springs[0].rest_length = 0"},
      {[&](Model& b) { b.springs.ks[0] = nan; }, "springs[0].ks = nan"},
      {[](Model& b) { b.springs.kd[0] = -1; }, "springs[0].kd = -1"},
      {[](Model& b) { b.mass[1] = 0; }, "mass[1] = 0"},
  };
  for (const auto& [mutate, message] : bad) {
    Model broken = sys.model();
    mutate(broken);
    try {
      broken.validate();
      ADD_FAILURE() << "no error for " << message;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0U) << e.what();
    }
  }
  EXPECT_NO_THROW(sys.model().validate());
}

TEST(Surface, ValidateNamesTheEntry) {
  Surface good;
  for (int p = 0; p < 3; ++p) good.add_particle_vertex(p);
  good.triangles.push_back({0, 1, 2});
  EXPECT_NO_THROW(good.validate(3, "bodies.a.surface"));
  const std::vector<std::pair<std::function<void(Surface&)>, std::string>> bad = {
      {[](Surface& b) { b.particles[1] = 3; }, "bodies.a.surface.particles[1] = 3"},
      {[](Surface& b) { b.weights[2] = std::numeric_limits<Real>::infinity(); },
       "bodies.a.surface.weights[2] = inf"},
      {[](Surface& b) { b.triangles[0][2] = 3; }, "bodies.a.surface.triangles[0] = 3"},
      {[](Surface& b) {
         b.offsets = {0, 1, 1, 3};  // vertex 1 without particles
       },
       "bodies.a.surface.vertex[1] = 1"},
  };
  for (const auto& [mutate, message] : bad) {
    Surface broken = good;
    mutate(broken);
    try {
      broken.validate(3, "bodies.a.surface");
      ADD_FAILURE() << "no error for " << message;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0U) << e.what();
    }
  }
}

}  // namespace
}  // namespace jelly
