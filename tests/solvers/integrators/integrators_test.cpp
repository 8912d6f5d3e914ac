#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/registry.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::make_sim;
using testing::TwoParticleSpring;

// Every registered integrator is tested the moment it is registered.
class EveryIntegrator : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Registry, EveryIntegrator, ::testing::ValuesIn(integrator_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// One particle held by an anchor spring (k, c) to the origin, no gravity: a damped oscillator,
// x(t) = x0 e^(-g t) (cos w t + g / w sin w t), g = c / 2m, w = sqrt(k / m - g^2). Every
// integrator follows it (first-order methods to O(h)).
TEST_P(EveryIntegrator, AnchorSpringIsADampedOscillator) {
  const Real m = 2, k = 200, c = 4, x0 = 0.1;
  Model model;
  model.mass = VecX::Constant(1, m);
  model.rest_position = VecX::Zero(3);
  model.gravity.setZero();
  State s;
  s.x = Vec3(x0, 0, 0);
  s.v = VecX::Zero(3);
  Simulator sim = make_sim(model, s, GetParam(), 1e-3);
  sim.set_anchors({AnchorSpring{0, Vec3::Zero(), k, c}});
  ASSERT_TRUE(sim.run_until(1.0).ok());
  const Real g = c / (2 * m), w = std::sqrt(k / m - g * g), t = sim.state().t;
  const Real exact = x0 * std::exp(-g * t) * (std::cos(w * t) + g / w * std::sin(w * t));
  EXPECT_NEAR(sim.state().x[0], exact, sim.integrator().order() >= 2 ? 1e-5 : 2e-3);
  EXPECT_EQ(sim.state().x[1], 0.0);
  EXPECT_THROW(sim.set_anchors({AnchorSpring{1, Vec3::Zero(), k, c}}), InputError);
  EXPECT_THROW(sim.set_anchors({AnchorSpring{0, Vec3::Zero(), -1, c}}), InputError);
}

// Free fall of the whole cube at rest: springs stay at rest length, so x(t) = x0 + v0 t + g t^2/2.
// Methods of order >= 2 are exact; both first-order Euler variants are off by exactly g t h / 2
// (xpbd by g t hs / 2 for its substep hs).
TEST_P(EveryIntegrator, FreeFallOfTheCube) {
  const Model model = build_cube(testing::small_cube(3));
  State s = rest_state(model);
  const Vec3 v0(1.0, 2.0, -0.5);
  for (int i = 0; i < model.num_particles(); ++i) particle(s.v, i) = v0;
  const Real h = 0.001, t_end = 1.0;
  Simulator sim = make_sim(model, s, GetParam(), h);
  ASSERT_TRUE(sim.run_until(t_end).ok());
  const Real t = sim.state().t;
  ASSERT_NEAR(t, t_end, 1e-12);
  // (xpbd: symplectic Euler per substep, of h / substeps.)
  const Real substep = GetParam() == "xpbd" ? h / XpbdOptions{}.substeps : h;
  const Real euler_error = model.gravity.norm() * t * substep / 2;
  for (int i = 0; i < model.num_particles(); ++i) {
    const Vec3 exact = Vec3(particle(s.x, i)) + v0 * t + 0.5 * model.gravity * t * t;
    const Real error = (Vec3(particle(sim.state().x, i)) - exact).norm();
    if (sim.integrator().order() >= 2) {
      EXPECT_LT(error, 1e-9) << "particle " << i;
    } else {
      EXPECT_NEAR(error, euler_error, 1e-9) << "particle " << i;
    }
    // arkode_dirk's default Newton solves (matrix-free CG, inexact Newton) stop at ARKODE's
    // tolerance: its velocities are exact to about 1e-8 (rtol 1e-6), the others' to rounding.
    const Real v_tolerance = GetParam() == "arkode_dirk" ? 2e-8 : 1e-9;
    EXPECT_LT((Vec3(particle(sim.state().v, i)) - (v0 + model.gravity * t)).norm(), v_tolerance);
  }
}

Real oscillator_error(const std::string& name, const TwoParticleSpring& sys, Real h, Real t_end) {
  Simulator sim = make_sim(sys.model(), sys.initial(), name, h);
  EXPECT_TRUE(sim.run_until(t_end).ok());
  const State& s = sim.state();
  const Real length = s.x[3] - s.x[0];
  const Real rate = s.v[3] - s.v[0];
  return std::hypot(length - sys.length(s.t), (rate - sys.length_rate(s.t)) / sys.omega0());
}

// The measured order of convergence (log2 of the error ratio when h halves) on a damped
// two-particle spring matches the integrator's order. Adaptive integrators choose their own
// internal steps: their tolerance convergence is tested in arkode_test.cpp instead.
TEST_P(EveryIntegrator, MeasuredOrderOfConvergence) {
  if (make_integrator(GetParam())->is_adaptive())
    GTEST_SKIP() << GetParam() << " is adaptive: h-convergence does not apply";
  TwoParticleSpring sys;
  sys.kd = 2;
  const Real e1 = oscillator_error(GetParam(), sys, 4e-3, 1.0);
  const Real e2 = oscillator_error(GetParam(), sys, 2e-3, 1.0);
  const Real e3 = oscillator_error(GetParam(), sys, 1e-3, 1.0);
  const int order = make_integrator(GetParam())->order();
  EXPECT_NEAR(std::log2(e1 / e2), order, 0.15) << e1 << " " << e2;
  EXPECT_NEAR(std::log2(e2 / e3), order, 0.1) << e2 << " " << e3;
}

// RK4 at a fine step reproduces the analytic frequency and the damped decay.
TEST(TwoParticleSpring, FrequencyAndDecayMatchTheory) {
  TwoParticleSpring sys;
  sys.kd = 1.5;  // gamma = 1.5 / s, omega_0 = sqrt(200) rad/s
  Simulator sim = make_sim(sys.model(), sys.initial(), "rk4", 1e-4);
  Real max_error = 0;
  testing::Probe probe([&](const Simulator& s) {
    const Real length = s.state().x[3] - s.state().x[0];
    max_error = std::max(max_error, std::abs(length - sys.length(s.state().t)));
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(2.0).ok());
  EXPECT_LT(max_error, 1e-10);
  // Upward zero crossings of r - l0 are one damped period apart.
  const Real period = 2 * M_PI / sys.omega_d();
  EXPECT_NEAR(period, 2 * M_PI / std::sqrt(200 - 2.25), 1e-12);
  Simulator undamped =
      make_sim(TwoParticleSpring{}.model(), TwoParticleSpring{}.initial(), "rk4", 1e-4);
  ASSERT_TRUE(undamped.run_until(2 * M_PI / std::sqrt(200.0)).ok());
  EXPECT_NEAR(undamped.state().x[3] - undamped.state().x[0], 1.1, 1e-7);  // back after a period
}

State spinning_cube(const Model& model) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(model);
  const Vec3 c = center_of_mass(model, s);
  const Vec3 omega(0.5, 1.0, -0.3);
  for (int i = 0; i < model.num_particles(); ++i) {
    auto x = particle(s.x, i);
    for (int k = 0; k < 3; ++k) x[k] += 0.05 * u(rng);
    particle(s.v, i) = Vec3(0.2, -0.1, 0.3) + omega.cross(Vec3(x) - c);
  }
  return s;
}

// Without terrain and gravity, internal forces are pairwise and central: every integrator keeps
// the linear momentum (a linear invariant) to rounding; symplectic Euler also keeps the angular
// momentum exactly, the others to their truncation error.
TEST_P(EveryIntegrator, MomentumWithoutTerrainOrGravity) {
  CubeSpec spec = testing::small_cube(3);
  spec.gravity.setZero();
  const Model model = build_cube(spec);
  const State s0 = spinning_cube(model);
  Simulator sim = make_sim(model, s0, GetParam(), 1e-3);
  ASSERT_TRUE(sim.run_until(1.0).ok());
  const Vec3 p0 = linear_momentum(model, s0), p1 = linear_momentum(model, sim.state());
  const Vec3 l0 = angular_momentum(model, s0), l1 = angular_momentum(model, sim.state());
  EXPECT_LT((p1 - p0).norm(), 1e-10 * p0.norm());
  if (GetParam() == "symplectic_euler") {
    EXPECT_LT((l1 - l0).norm(), 1e-10 * l0.norm());
  } else {
    EXPECT_LT((l1 - l0).norm(), 2e-2 * l0.norm());
  }
}

// Symplectic Euler without damping: the energy error oscillates without drift, and its size is
// first order in h (it conserves a modified energy h-close to the true one).
Real max_energy_error(const Model& model, const State& s0, Real h, Real from, Real to) {
  const Real e0 = total_energy(model, s0);
  Real worst = 0;
  Simulator sim = make_sim(model, s0, "symplectic_euler", h);
  testing::Probe probe([&](const Simulator& s) {
    if (s.state().t >= from) worst = std::max(worst, std::abs(total_energy(model, s.state()) - e0));
  });
  sim.add_observer(probe);
  EXPECT_TRUE(sim.run_until(to).ok());
  return worst;
}

TEST(Energy, BoundedForSymplecticEuler) {
  CubeSpec spec = testing::small_cube(3);
  for (auto& c : spec.springs) c.kd = 0;
  spec.gravity.setZero();
  const Model model = build_cube(spec);
  const State s0 = spinning_cube(model);
  const Real first = max_energy_error(model, s0, 1e-3, 0, 5);
  const Real late = max_energy_error(model, s0, 1e-3, 5, 10);
  const Real halved = max_energy_error(model, s0, 5e-4, 0, 5);
  EXPECT_LT(late, 1.2 * first);           // no drift
  EXPECT_NEAR(halved / first, 0.5, 0.1);  // O(h)
}

// With dampers, the total energy never grows and the internal part (all but the kinetic energy
// of the centre of mass, which nothing can remove without terrain or gravity) decays.
TEST(Energy, DecaysWithDamping) {
  CubeSpec spec = testing::small_cube(3);
  spec.gravity.setZero();
  const Model model = build_cube(spec);
  const State s0 = spinning_cube(model);
  const Real com_energy = 0.5 * linear_momentum(model, s0).squaredNorm() / model.mass.sum();
  Simulator sim = make_sim(model, s0, "rk4", 1e-3, 0.01);
  Real previous = total_energy(model, s0);
  const Real first = previous;
  bool grew = false;
  testing::Probe probe([&](const Simulator& s) {
    const Real e = total_energy(model, s.state());
    grew = grew || e > previous + 1e-12 * std::abs(previous);
    previous = e;
  });
  sim.add_observer(probe);
  ASSERT_TRUE(sim.run_until(2.0).ok());
  EXPECT_FALSE(grew);
  EXPECT_LT(previous - com_energy, 0.5 * (first - com_energy));
}

}  // namespace
}  // namespace jelly
