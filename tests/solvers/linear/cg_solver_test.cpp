#include <jelly/solvers/linear/detail/cg_solver.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "solvers/linear/linear_systems.hpp"

namespace jelly {
namespace {

using testing::backward_euler_system;
using testing::dense_solution;
using testing::LinearSystem;
using testing::solve_with;

// A symmetric positive definite matrix without the 3x3-block pattern (CG's scalar Jacobi path):
// the 1D Laplacian plus a varying diagonal, n x n.
SparseMatrix scalar_spd(int n) {
  std::vector<Eigen::Triplet<Real>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0 + 0.01 * i);
    if (i + 1 < n) {
      t.emplace_back(i, i + 1, -1.0);
      t.emplace_back(i + 1, i, -1.0);
    }
  }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

// CG stops at |b - A x| <= tolerance |b| and its x is then the dense solution to within the
// condition number times the tolerance, for both preconditioners and both storage paths.
TEST(CgSolver, ConvergesToTheDenseSolution) {
  const LinearSystem s =
      backward_euler_system(4, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  const SparseMatrix scalar = scalar_spd(50);
  const VecX scalar_b = VecX::LinSpaced(50, -1, 2);
  for (CgPreconditioner p : {CgPreconditioner::kJacobi, CgPreconditioner::kLaggedCholesky}) {
    for (Real tolerance : {1e-6, 1e-10}) {
      for (const auto& [a, b] : {std::pair<const SparseMatrix&, const VecX&>(s.a, s.b),
                                 std::pair<const SparseMatrix&, const VecX&>(scalar, scalar_b)}) {
        CgOptions o;
        o.preconditioner = p;
        o.tolerance = tolerance;
        CgSolver cg(o);
        const VecX x = solve_with(cg, a, b);
        const VecX exact = dense_solution(a, b);
        EXPECT_LE((b - a * x).norm(), tolerance * b.norm()) << cg.name();
        const Eigen::VectorXd eig =
            Eigen::MatrixXd(a).selfadjointView<Eigen::Lower>().eigenvalues();
        const Real condition = eig.maxCoeff() / eig.minCoeff();
        EXPECT_LE((x - exact).norm(), condition * tolerance * exact.norm()) << cg.name();
      }
    }
  }
}

// With too few iterations CG says so: kNotConverged, the iterations it did and its residual.
TEST(CgSolver, ReportsNonConvergence) {
  const LinearSystem s =
      backward_euler_system(4, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  CgOptions o;
  o.max_iterations = 2;
  o.tolerance = 1e-12;
  CgSolver cg(o);
  ASSERT_TRUE(cg.analyze(s.a).ok());
  ASSERT_TRUE(cg.factorize(s.a).ok());
  VecX x = VecX::Zero(s.b.size());
  const LinearResult r = cg.solve(s.b, x);
  EXPECT_EQ(r.status, LinearStatus::kNotConverged);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_GT(r.residual, 1e-12);
  EXPECT_NEAR(r.residual, (s.b - s.a * x).norm() / s.b.norm(), 1e-12);
  EXPECT_NE(r.message.find("after 2 iterations"), std::string::npos) << r.message;
  EXPECT_EQ(cg.counters().cg_iterations, 2);
}

// A start at the solution costs no iteration; b = 0 gives x = 0.
TEST(CgSolver, WarmStartAndZeroRightHandSide) {
  const LinearSystem s =
      backward_euler_system(3, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  CgSolver cg;
  VecX x = solve_with(cg, s.a, s.b);
  const long iterations = cg.counters().cg_iterations;
  EXPECT_GT(iterations, 0);
  LinearResult r = cg.solve(s.b, x);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.iterations, 0);
  r = cg.solve(VecX::Zero(s.b.size()), x);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(x, VecX::Zero(s.b.size()));
  EXPECT_EQ(cg.counters().solves, 3);
}

// CG preconditioned by the factor of an earlier matrix solves a later one in a few iterations
// without refactoring; invalidate() forces a fresh factor.
TEST(CgSolver, LaggedFactorPreconditionsALaterMatrix) {
  const LinearSystem s0 =
      backward_euler_system(5, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  const LinearSystem s1 =
      backward_euler_system(5, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed, 0.97);
  CgOptions o;
  o.preconditioner = CgPreconditioner::kLaggedCholesky;
  o.tolerance = 1e-12;
  CgSolver cg(o);
  ASSERT_TRUE(cg.analyze(s0.a).ok());
  ASSERT_TRUE(cg.factorize(s0.a).ok());
  ASSERT_TRUE(cg.factorize(s1.a).ok());  // keeps the factor of s0
  VecX x = VecX::Zero(s1.b.size());
  const LinearResult r = cg.solve(s1.b, x);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(cg.counters().factorizations, 1);
  EXPECT_EQ(cg.preconditioner_factorizations(), 1);
  EXPECT_GT(r.iterations, 1);
  EXPECT_LT(r.iterations, 20);
  EXPECT_LT((s1.a * x - s1.b).norm(), 1e-11 * s1.b.norm());
  cg.invalidate();
  ASSERT_TRUE(cg.factorize(s1.a).ok());
  EXPECT_EQ(cg.preconditioner_factorizations(), 2);
}

// A crushed jelly without a definiteness fix: non-positive curvature (or a non-positive
// diagonal block) is the status kNotPositiveDefinite, not a wrong answer.
TEST(CgSolver, NotPositiveDefiniteIsAStatus) {
  const LinearSystem s = backward_euler_system(4, 100000, 1.0 / 30, DefinitenessFix::kNone, 0.4);
  CgSolver cg;
  ASSERT_TRUE(cg.analyze(s.a).ok());
  VecX x = VecX::Zero(s.b.size());
  LinearResult c = cg.factorize(s.a);
  if (c.ok()) c = cg.solve(s.b, x);
  EXPECT_EQ(c.status, LinearStatus::kNotPositiveDefinite) << c.message;
  EXPECT_NE(c.message.find("positive"), std::string::npos) << c.message;
}

TEST(CgSolver, MisuseIsInvalidInput) {
  const LinearSystem s =
      backward_euler_system(3, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  CgSolver cg;
  VecX x = VecX::Zero(s.b.size());
  ASSERT_TRUE(cg.analyze(s.a).ok());
  EXPECT_EQ(cg.solve(s.b, x).status, LinearStatus::kInvalidInput);  // before factorize
  ASSERT_TRUE(cg.factorize(s.a).ok());
  VecX short_x = VecX::Zero(3);
  EXPECT_EQ(cg.solve(s.b, short_x).status, LinearStatus::kInvalidInput);
  EXPECT_EQ(cg.factorize(scalar_spd(5)).status, LinearStatus::kInvalidInput);  // another size
  EXPECT_EQ(cg.analyze(SparseMatrix(3, 4)).status, LinearStatus::kInvalidInput);
}

// MatrixFreeCg resumes a converged solve (contact screening's finishing solve): a solve to 1e-3
// resumed to 1e-10 gives the bits and the total iterations of one solve to 1e-10, for 1 and 2
// threads; resuming without a converged solve is refused.
TEST(MatrixFreeCg, ResumingIsOneUninterruptedSolve) {
  const testing::LinearSystem s =
      testing::backward_euler_system(6, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  const int particles = static_cast<int>(s.a.rows() / 3);
  const MatrixFreeCg::Product apply = [&](const VecX& in, VecX& out) { out = s.a * in; };
  const auto block = [&](int i, Real d[9]) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) d[3 * r + c] = s.a.coeff(3 * i + r, 3 * i + c);
  };
  for (int threads : {1, 2}) {
    MatrixFreeCg one, two;
    ASSERT_TRUE(one.set_diagonal_blocks(particles, block, threads).ok());
    ASSERT_TRUE(two.set_diagonal_blocks(particles, block, threads).ok());
    VecX x1 = VecX::Zero(s.b.size()), x2 = x1;
    const LinearResult whole = one.solve(apply, s.b, x1, 1e-10, 1000, threads);
    const LinearResult loose = two.solve(apply, s.b, x2, 1e-3, 1000, threads);
    ASSERT_TRUE(whole.ok() && loose.ok());
    EXPECT_LT(loose.iterations, whole.iterations);
    const LinearResult rest = two.solve(apply, s.b, x2, 1e-10, 1000, threads, true);
    ASSERT_TRUE(rest.ok()) << rest.message;
    EXPECT_EQ(loose.iterations + rest.iterations, whole.iterations);
    EXPECT_EQ(x1, x2);  // bit for bit
    EXPECT_LE((s.b - s.a * x2).norm(), 1e-10 * s.b.norm());
    // Resuming to a tolerance already met does nothing and keeps the stop: a further resume to
    // 1e-12 is still one solve to 1e-12 (direction and all).
    EXPECT_EQ(two.solve(apply, s.b, x2, 1e-10, 1000, threads, true).iterations, 0);
    VecX x3 = VecX::Zero(s.b.size());
    const LinearResult tight = one.solve(apply, s.b, x3, 1e-12, 1000, threads);
    const LinearResult tighter = two.solve(apply, s.b, x2, 1e-12, 1000, threads, true);
    ASSERT_TRUE(tight.ok() && tighter.ok());
    EXPECT_GT(tighter.iterations, 0);
    EXPECT_EQ(loose.iterations + rest.iterations + tighter.iterations, tight.iterations);
    EXPECT_EQ(x2, x3);
  }
  // b = 0: x = 0, and resuming it has nothing to do (residual 0, not 0 / 0).
  {
    MatrixFreeCg cg;
    ASSERT_TRUE(cg.set_diagonal_blocks(particles, block, 1).ok());
    const VecX zero = VecX::Zero(s.b.size());
    VecX x = VecX::Ones(s.b.size());
    ASSERT_TRUE(cg.solve(apply, zero, x, 1e-3, 1000, 1).ok());
    const LinearResult again = cg.solve(apply, zero, x, 1e-10, 1000, 1, true);
    EXPECT_TRUE(again.ok());
    EXPECT_EQ(again.iterations, 0);
    EXPECT_EQ(again.residual, 0);
    EXPECT_EQ(x, zero);
  }
  // A new preconditioner ends what could be resumed.
  {
    MatrixFreeCg cg;
    ASSERT_TRUE(cg.set_diagonal_blocks(particles, block, 1).ok());
    VecX x = VecX::Zero(s.b.size());
    ASSERT_TRUE(cg.solve(apply, s.b, x, 1e-3, 1000, 1).ok());
    ASSERT_TRUE(cg.set_diagonal_blocks(particles, block, 1).ok());
    EXPECT_EQ(cg.solve(apply, s.b, x, 1e-10, 1000, 1, true).status, LinearStatus::kInvalidInput);
  }
  MatrixFreeCg fresh;
  ASSERT_TRUE(fresh.set_diagonal_blocks(particles, block, 1).ok());
  VecX x = VecX::Zero(s.b.size());
  EXPECT_EQ(fresh.solve(apply, s.b, x, 1e-10, 1000, 1, true).status, LinearStatus::kInvalidInput);
  EXPECT_EQ(fresh.solve(apply, s.b, x, 1e-10, 2, 1).status, LinearStatus::kNotConverged);
  EXPECT_EQ(fresh.solve(apply, s.b, x, 1e-10, 1000, 1, true).status, LinearStatus::kInvalidInput);
}

}  // namespace
}  // namespace jelly
