// implicit_euler_ceres: backward Euler as nonlinear least squares, checked against analytic
// answers and against Newton's method on the same equations.
#include <jelly/fit/detail/implicit_euler_ceres.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/simulator.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

Simulator make_ceres_sim(const Model& model, const State& state, Real dt) {
  SimulatorOptions options;
  options.dt = dt;
  return Simulator(model, state, make_implicit_euler_ceres(), options);
}

TEST(ImplicitEulerCeres, Identity) {
  auto integrator = make_fit_integrator("implicit_euler_ceres");
  EXPECT_EQ(integrator->name(), "implicit_euler_ceres");
  EXPECT_EQ(integrator->order(), 1);
  EXPECT_TRUE(integrator->is_implicit());
  EXPECT_EQ(make_fit_integrator("rk4")->name(), "rk4");
  EXPECT_THROW(make_fit_integrator("rk5"), InputError);
}

// Backward Euler in free fall: v_n = v_0 + n h g, x_n = x_0 + v_0 t + g t^2 / 2 + g t h / 2.
TEST(ImplicitEulerCeres, FreeFallErrorIsGTHOverTwo) {
  Model model;
  model.mass = VecX::Constant(2, 1.5);
  model.rest_position = VecX::Zero(6);
  model.rest_position[3] = 1;
  model.springs.add(0, 1, 1, {200, 0}, SpringType::kStructural);
  State s = rest_state(model);
  s.v = VecX::Zero(6);
  const Real h = 0.01;
  Simulator sim = make_ceres_sim(model, s, h);
  ASSERT_EQ(sim.run_until(0.5).status, RunStatus::kCompleted);
  const Real t = sim.state().t;
  const Real g = model.gravity.y();
  for (int i = 0; i < 2; ++i) {
    const Real exact = model.rest_position[3 * i + 1] + 0.5 * g * t * t;
    EXPECT_NEAR(sim.state().x[3 * i + 1] - exact, 0.5 * g * t * h, 1e-9);
    EXPECT_NEAR(sim.state().v[3 * i + 1], g * t, 1e-9);
    EXPECT_NEAR(sim.state().x[3 * i], model.rest_position[3 * i], 1e-12);
  }
  EXPECT_GT(sim.integrator().statistics().at("ceres_iterations"), 0);
}

// First order: the error of the spring length at t = 0.5 halves when h halves.
TEST(ImplicitEulerCeres, FirstOrderOnTwoParticleSpring) {
  const testing::TwoParticleSpring system;
  const Real t_end = 0.5;
  std::vector<Real> errors;
  for (Real h : {4e-3, 2e-3, 1e-3}) {
    Simulator sim = make_ceres_sim(system.model(), system.initial(), h);
    ASSERT_EQ(sim.run_until(t_end).status, RunStatus::kCompleted);
    const Real length = sim.state().x[3] - sim.state().x[0];
    errors.push_back(std::abs(length - system.length(sim.state().t)));
  }
  for (size_t k = 1; k < errors.size(); ++k) {
    const Real ratio = errors[k - 1] / errors[k];
    EXPECT_GT(ratio, 1.8) << "h ratio " << k;
    EXPECT_LT(ratio, 2.2) << "h ratio " << k;
  }
}

TEST(ImplicitEulerCeres, RejectsDampedSprings) {
  testing::TwoParticleSpring system;
  system.kd = 1;
  Simulator sim = make_ceres_sim(system.model(), system.initial(), 1e-3);
  try {
    sim.step();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("springs[0].kd"), std::string::npos) << e.what();
  }
}

// Newton's method on the backward-Euler equations g(x) = M (x - y) / h^2 - f_spring(x) = 0,
// y = x_n + h v_n + h^2 M^-1 f_gravity, with a dense Jacobian by central differences of the
// spring forces: a reference written independently of both integrators.
State dense_newton_step(const Model& model, const State& s, Real h) {
  const int n = model.num_dofs();
  VecX y(n), m(n);
  for (int i = 0; i < model.num_particles(); ++i) {
    m.segment<3>(3 * i).setConstant(model.mass[i]);
    particle(y, i) = particle(s.x, i) + h * particle(s.v, i) + h * h * model.gravity;
  }
  const VecX zero = VecX::Zero(n);
  auto g = [&](const VecX& x) {
    VecX f = VecX::Zero(n);
    add_spring_forces(model, x, zero, f);
    return VecX(m.cwiseProduct(x - y) / (h * h) - f);
  };
  VecX x = s.x + h * s.v;
  for (int it = 0; it < 30; ++it) {
    const VecX r = g(x);
    if (r.norm() < 1e-13 * (1 + m.cwiseProduct(y).norm() / (h * h))) break;
    Eigen::MatrixXd jac(n, n);
    for (int c = 0; c < n; ++c) {
      VecX xp = x, xm = x;
      const Real d = 1e-6;
      xp[c] += d;
      xm[c] -= d;
      jac.col(c) = (g(xp) - g(xm)) / (2 * d);
    }
    x -= jac.fullPivLu().solve(r);
  }
  State next;
  next.t = s.t + h;
  next.v = (x - s.x) / h;
  next.x = x;
  return next;
}

// A 3x3x3 cube, undamped, squashed and spinning in gravity, no terrain.
Model undamped_cube() {
  CubeSpec spec = testing::small_cube(3, 1, Vec3(0, 1, 0));
  for (auto& c : spec.springs) c = {1200, 0};
  return build_cube(spec);
}

State deformed_state(const Model& model) {
  State s = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i) {
    s.x[3 * i + 1] = 1 + 0.8 * (s.x[3 * i + 1] - 1);  // squashed by 20 % along y
    s.v[3 * i] = -2 * (s.x[3 * i + 1] - 1.5);         // sheared
    s.v[3 * i + 2] = 0.5 * std::sin(3.0 * i);
  }
  return s;
}

TEST(ImplicitEulerCeres, AgreesWithDenseNewton) {
  const Model model = undamped_cube();
  const Real h = 0.01;
  State reference = deformed_state(model);
  Simulator sim = make_ceres_sim(model, reference, h);
  for (int step = 0; step < 5; ++step) {
    reference = dense_newton_step(model, reference, h);
    ASSERT_TRUE(sim.step().ok);
    EXPECT_LT((sim.state().x - reference.x).lpNorm<Eigen::Infinity>(), 1e-8) << "step " << step;
    // v = (x - x_n) / h: the position agreement divided by h.
    EXPECT_LT((sim.state().v - reference.v).lpNorm<Eigen::Infinity>(), 1e-8 / h) << "step " << step;
  }
  // The cube did deform: the comparison is not between two rigid motions.
  EXPECT_GT((sim.state().x - deformed_state(model).x).norm(), 0.1);
}

// The fully nonlinear implicit_euler of the solvers (Newton on the velocity form, sparse Cholesky)
// and the Ceres least-squares solve of the position form reach the same backward-Euler step.
TEST(ImplicitEulerCeres, AgreesWithNewtonImplicitEuler) {
  const Model model = undamped_cube();
  const Real h = 0.01;
  IntegratorOptions newton;
  newton.implicit.newton_iterations = 50;
  newton.implicit.newton_tolerance = 1e-13;
  newton.implicit.linear_solver =
      ImplicitLinearSolver::kCholmod;  // direct solves: no CG tolerance in the way
  SimulatorOptions options;
  options.dt = h;
  Simulator reference(model, deformed_state(model), make_integrator("implicit_euler", newton),
                      options);
  Simulator sim = make_ceres_sim(model, deformed_state(model), h);
  Real max_dx = 0, max_dv = 0;
  for (int step = 0; step < 10; ++step) {
    ASSERT_TRUE(reference.step().ok);
    ASSERT_TRUE(sim.step().ok);
    EXPECT_LT((sim.state().x - reference.state().x).lpNorm<Eigen::Infinity>(), 1e-8)
        << "step " << step;
    EXPECT_LT((sim.state().v - reference.state().v).lpNorm<Eigen::Infinity>(), 1e-8 / h)
        << "step " << step;
    max_dx = std::max(max_dx, (sim.state().x - reference.state().x).lpNorm<Eigen::Infinity>());
    max_dv = std::max(max_dv, (sim.state().v - reference.state().v).lpNorm<Eigen::Infinity>());
  }
  std::cout << "implicit_euler_ceres vs implicit_euler (Newton), 10 steps of " << h
            << " s: max |dx| = " << max_dx << " m, max |dv| = " << max_dv << " m/s\n";
  EXPECT_EQ(reference.integrator().statistics().at("newton_not_converged"), 0);
  // Newton did iterate: the linearized step alone would differ.
  EXPECT_GT(reference.integrator().statistics().at("newton_iterations"), 10);
}

}  // namespace
}  // namespace jelly
