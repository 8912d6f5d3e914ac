#pragma once
// Symmetric test systems for the linear solvers: the backward-Euler matrix of a deformed, moving
// cube (3x3 blocks, as implicit_euler builds it) and its right-hand side.
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

#include "support/systems.hpp"

namespace jelly::testing {

struct LinearSystem {
  Model model;
  SparseMatrix a;
  VecX b;
};

// (M - h D - h^2 K) and h (f + h K v) of an n^3 cube of stiffness ks, squeezed about its centre
// of mass by `squeeze`, with random displacements and velocities (seeded: always the same).
inline LinearSystem backward_euler_system(int n, Real ks, Real h, DefinitenessFix fix,
                                          Real squeeze = 1.0) {
  CubeSpec spec = small_cube(n, 1.0);
  for (auto& c : spec.springs) c = SpringCoefficients{ks, 50};
  LinearSystem s;
  s.model = build_cube(spec);
  State st = rest_state(s.model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  const Vec3 c = center_of_mass(s.model, st);
  for (int i = 0; i < s.model.num_particles(); ++i) {
    particle(st.x, i) = c + squeeze * (Vec3(particle(st.x, i)) - c);
    for (int k = 0; k < 3; ++k) {
      st.x[3 * i + k] += 0.05 / (n - 1) * u(rng);
      st.v[3 * i + k] = 0.5 * u(rng);
    }
  }
  SpringJacobian jacobian(s.model);
  s.a = jacobian.make_matrix();
  VecX f(s.model.num_dofs()), kv(s.model.num_dofs());
  compute_forces(s.model, st.x, st.v, f);
  JacobianOptions o;
  o.definiteness = fix;
  jacobian.assemble_system(s.model, st.x, st.v, o, h, h * h, s.a, st.v, kv);
  s.b = h * (f + h * kv);
  return s;
}

// Analyses, factorizes and solves from x = 0, expecting success at each stage.
inline VecX solve_with(LinearSolver& solver, const SparseMatrix& a, const VecX& b) {
  EXPECT_TRUE(solver.analyze(a).ok()) << solver.name();
  const LinearResult f = solver.factorize(a);
  EXPECT_TRUE(f.ok()) << solver.name() << ": " << f.message;
  VecX x = VecX::Zero(b.size());
  const LinearResult r = solver.solve(b, x);
  EXPECT_TRUE(r.ok()) << solver.name() << ": " << r.message;
  return x;
}

// The dense Cholesky solution (the reference).
inline VecX dense_solution(const SparseMatrix& a, const VecX& b) {
  return Eigen::MatrixXd(a).llt().solve(b);
}

}  // namespace jelly::testing
