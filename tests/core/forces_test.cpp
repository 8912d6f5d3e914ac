#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <random>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

// A 3x3x3 cube with randomly displaced particles and random velocities.
State perturbed(const Model& m, unsigned seed, Real dx = 0.1, Real dv = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(m);
  for (int i = 0; i < s.x.size(); ++i) {
    s.x[i] += dx * u(rng);
    s.v[i] = dv * u(rng);
  }
  return s;
}

class SpringForceGradient : public ::testing::TestWithParam<Real> {};

// Without damping (or at zero velocity), the spring force is -grad of the elastic energy.
TEST_P(SpringForceGradient, MatchesCentralDifferences) {
  CubeSpec spec = testing::small_cube(3);
  for (auto& c : spec.springs) c.ks = GetParam();
  const Model m = build_cube(spec);
  const State s = perturbed(m, 7);
  VecX f = VecX::Zero(m.num_dofs());
  add_spring_forces(m, s.x, VecX::Zero(m.num_dofs()), f);
  const Real h = 1e-6;
  VecX x = s.x;
  for (int k = 0; k < x.size(); ++k) {
    x[k] = s.x[k] + h;
    const Real ep = elastic_energy(m, x);
    x[k] = s.x[k] - h;
    const Real em = elastic_energy(m, x);
    x[k] = s.x[k];
    const Real grad = (ep - em) / (2 * h);
    EXPECT_NEAR(f[k], -grad, 1e-6 * (1 + std::abs(f[k]))) << "component " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(Stiffness, SpringForceGradient, ::testing::Values(10.0, 1400.0, 1e5));

TEST(Forces, DamperMatchesReportFormula) {
  testing::TwoParticleSpring sys;
  sys.ks = 0;
  sys.kd = 7;
  const Model m = sys.model();
  State s = sys.initial();
  s.x.segment<3>(3) = Vec3(1.0, 0.5, -0.2);
  s.v.segment<3>(0) = Vec3(0.3, -0.1, 0.2);
  s.v.segment<3>(3) = Vec3(-0.4, 0.6, 0.1);
  VecX f = VecX::Zero(6);
  add_spring_forces(m, s.x, s.v, f);
  const Vec3 xa = s.x.segment<3>(0), xb = s.x.segment<3>(3);
  const Vec3 va = s.v.segment<3>(0), vb = s.v.segment<3>(3);
  const Vec3 d = (xa - xb).normalized();
  const Vec3 expected = -sys.kd * (va - vb).dot(d) * d;
  EXPECT_LT((f.segment<3>(0) - expected).norm(), 1e-14);
  EXPECT_LT((f.segment<3>(3) + expected).norm(), 1e-14);
}

// Internal forces are pairwise and central: no net force or torque.
TEST(Forces, InternalForcesHaveNoNetForceOrTorque) {
  const Model m = build_cube(testing::small_cube(4));
  const State s = perturbed(m, 3);
  VecX f = VecX::Zero(m.num_dofs());
  add_spring_forces(m, s.x, s.v, f);
  Vec3 net = Vec3::Zero(), torque = Vec3::Zero();
  Real scale = 0;
  for (int i = 0; i < m.num_particles(); ++i) {
    net += particle(f, i);
    torque += Vec3(particle(s.x, i)).cross(Vec3(particle(f, i)));
    scale += particle(f, i).norm();
  }
  EXPECT_LT(net.norm(), 1e-12 * scale);
  EXPECT_LT(torque.norm(), 1e-12 * scale);
}

TEST(Forces, GravityOnly) {
  const Model m = build_cube(testing::small_cube(3));
  const State s = rest_state(m);
  VecX f(m.num_dofs());
  compute_forces(m, s.x, s.v, f);
  for (int i = 0; i < m.num_particles(); ++i) {
    EXPECT_NEAR(f[3 * i], 0, 1e-9);
    EXPECT_NEAR(f[3 * i + 1], -9.8, 1e-9);
    EXPECT_NEAR(f[3 * i + 2], 0, 1e-9);
  }
}

}  // namespace
}  // namespace jelly
