// Every force, jelly's own and a user's, checked against central differences of its forces
// through the one Force interface (check_force_jacobian).
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include <jelly/core/detail/builtin_forces.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

// A spring from particle p to a fixed point with its Jacobian (a user's force).
class SpringToPoint final : public Force {
 public:
  SpringToPoint(int p, Vec3 target, Real k, Real c) : p_(p), target_(target), k_(k), c_(c) {}
  std::string name() const override { return "spring_to_point"; }
  void add_forces(Real, const VecX& x, const VecX& v, VecX& f) const override {
    f.segment<3>(3 * p_) -= k_ * (x.segment<3>(3 * p_) - target_) + c_ * v.segment<3>(3 * p_);
  }
  bool has_jacobian() const override { return true; }
  void add_jacobian(Real, const VecX&, const VecX&, ForceJacobian& j) const override {
    j.add(p_, p_, -k_ * Mat3::Identity(), -c_ * Mat3::Identity());
  }

 private:
  int p_;
  Vec3 target_;
  Real k_, c_;
};

// A cube in a perturbed, moving state (stretched and compressed springs, closing dampers).
struct Perturbed {
  Model model;
  State state;
};
Perturbed perturbed_cube() {
  Perturbed p;
  p.model = build_cube(testing::small_cube(3));
  ExternalForce wind;
  wind.kind = ExternalForceKind::kWind;
  wind.particles = {0, 4, 7};
  wind.vector = Vec3(1, 0, 0.5);
  wind.drag = 0.8;
  p.model.external_forces.push_back(wind);
  p.state = rest_state(p.model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-0.05, 0.05);
  for (Eigen::Index k = 0; k < p.state.x.size(); ++k) {
    p.state.x[k] += u(rng);
    p.state.v[k] = 20 * u(rng);
  }
  return p;
}

TEST(ForceJacobians, EveryBuiltInForceMatchesCentralDifferences) {
  const Perturbed p = perturbed_cube();
  AnchorSprings anchors{{2, Vec3(0.1, 1, 0), 50, 3}};
  const auto forces = builtin_forces(p.model, anchors);
  ASSERT_EQ(forces.size(), 4u);
  for (const auto& force : forces) {
    const JacobianCheck c = check_force_jacobian(*force, 0.3, p.state.x, p.state.v);
    EXPECT_LT(c.dfdx_error, 1e-7) << force->name();
    EXPECT_LT(c.dfdv_error, 1e-7) << force->name();
  }
}

TEST(ForceJacobians, BuiltInForcesSumToTheModelsForces) {
  const Perturbed p = perturbed_cube();
  VecX sum = VecX::Zero(p.model.num_dofs()), expected = sum;
  for (const auto& force : builtin_forces(p.model))
    force->add_forces(0.3, p.state.x, p.state.v, sum);
  compute_forces(p.model, p.state.x, p.state.v, expected);
  add_external_forces(p.model.external_forces, p.model.mass, 0.3, p.state.v, expected);
  EXPECT_LT((sum - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
}

TEST(ForceJacobians, AUsersForceIsCheckedTheSameWay) {
  const Perturbed p = perturbed_cube();
  const SpringToPoint good(3, Vec3(0, 2, 0), 1e4, 5);
  const JacobianCheck c = check_force_jacobian(good, 0, p.state.x, p.state.v);
  // Central differences of forces of ~500 N with steps of 1e-6 carry rounding of ~1e-8.
  EXPECT_LT(c.dfdx_error, 1e-6);
  EXPECT_LT(c.dfdv_error, 1e-6);
  EXPECT_EQ(c.dfdx_scale, 1e4);

  // A wrong Jacobian (the damping's sign flipped) is caught.
  class Wrong final : public Force {
   public:
    std::string name() const override { return "wrong"; }
    void add_forces(Real, const VecX&, const VecX& v, VecX& f) const override {
      f.segment<3>(0) -= 2 * v.segment<3>(0);
    }
    bool has_jacobian() const override { return true; }
    void add_jacobian(Real, const VecX&, const VecX&, ForceJacobian& j) const override {
      j.add(0, 0, Mat3::Zero(), 2 * Mat3::Identity());
    }
  };
  EXPECT_GT(check_force_jacobian(Wrong(), 0, p.state.x, p.state.v).dfdv_error, 0.5);
}

TEST(ForceJacobians, BlocksOutsideTheModelAreRefusedNamingTheForce) {
  ForceJacobian j;
  j.add(0, 9, Mat3::Zero(), Mat3::Zero());
  try {
    j.validate(8, "magnet");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("force 'magnet' Jacobian block = (0, 9)"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace jelly
