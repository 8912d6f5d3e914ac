#include <jelly/solvers/linear/detail/cholmod_solver.hpp>

#include <gtest/gtest.h>

#include "solvers/linear/linear_systems.hpp"

namespace jelly {
namespace {

using testing::backward_euler_system;
using testing::dense_solution;
using testing::LinearSystem;
using testing::solve_with;

// Both factorization paths (simplicial and supernodal) and every ordering give the dense
// solution to rounding.
TEST(CholmodSolver, SolvesToRounding) {
  const LinearSystem s =
      backward_euler_system(4, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  const VecX exact = dense_solution(s.a, s.b);
  for (CholmodOrdering o : {CholmodOrdering::kAmd, CholmodOrdering::kMetis,
                            CholmodOrdering::kNesdis, CholmodOrdering::kBest}) {
    for (int supernodal_min_rows : {0, 1 << 30}) {
      CholmodOptions options;
      options.ordering = o;
      options.supernodal_min_rows = supernodal_min_rows;
      CholmodSolver solver(options);
      const VecX x = solve_with(solver, s.a, s.b);
      EXPECT_LT((x - exact).norm(), 1e-12 * exact.norm())
          << cholmod_ordering_name(o) << " " << supernodal_min_rows;
      EXPECT_LT((s.a * x - s.b).norm(), 1e-13 * s.b.norm());
      EXPECT_GT(solver.factor_non_zeros(), 0);
    }
  }
}

// One symbolic analysis for the pattern; every later matrix of that pattern is a numeric
// factorization only, and each is solved exactly.
TEST(CholmodSolver, AnalysesOnceAndRefactorizesNumerically) {
  CholmodSolver solver;
  const LinearSystem first =
      backward_euler_system(4, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  ASSERT_TRUE(solver.analyze(first.a).ok());
  EXPECT_FALSE(solver.factorized());
  for (Real squeeze : {1.0, 0.97, 0.9}) {
    const LinearSystem s =
        backward_euler_system(4, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed, squeeze);
    ASSERT_TRUE(solver.factorize(s.a).ok());
    EXPECT_TRUE(solver.factorized());
    VecX x = VecX::Zero(s.b.size());
    ASSERT_TRUE(solver.solve(s.b, x).ok());
    EXPECT_LT((x - dense_solution(s.a, s.b)).norm(), 1e-12 * x.norm()) << squeeze;
  }
  EXPECT_EQ(solver.counters().analyses, 1);
  EXPECT_EQ(solver.counters().factorizations, 3);
  EXPECT_EQ(solver.counters().solves, 3);
  EXPECT_EQ(solver.counters().cg_iterations, 0);
}

// A matrix that is not positive definite is the status kNotPositiveDefinite with CHOLMOD's
// reason; the failed factor is not used, and the next good matrix factorizes again.
TEST(CholmodSolver, NotPositiveDefiniteIsAStatus) {
  const LinearSystem bad = backward_euler_system(4, 100000, 1.0 / 30, DefinitenessFix::kNone, 0.4);
  const LinearSystem good =
      backward_euler_system(4, 100000, 1.0 / 30, DefinitenessFix::kClampCompressed, 0.4);
  for (int supernodal_min_rows : {0, 1 << 30}) {
    CholmodOptions options;
    options.supernodal_min_rows = supernodal_min_rows;
    CholmodSolver cholmod(options);
    ASSERT_TRUE(cholmod.analyze(bad.a).ok());
    const LinearResult r = cholmod.factorize(bad.a);
    EXPECT_EQ(r.status, LinearStatus::kNotPositiveDefinite);
    EXPECT_NE(r.message.find("CHOLMOD"), std::string::npos) << r.message;
    EXPECT_NE(r.message.find("not positive definite"), std::string::npos) << r.message;
    EXPECT_FALSE(cholmod.factorized());
    VecX x = VecX::Zero(bad.b.size());
    EXPECT_EQ(cholmod.solve(bad.b, x).status, LinearStatus::kInvalidInput);  // no factor
    ASSERT_TRUE(cholmod.factorize(good.a).ok());
    ASSERT_TRUE(cholmod.solve(good.b, x).ok());
    EXPECT_LT((good.a * x - good.b).norm(), 1e-12 * good.b.norm());
  }
}

TEST(CholmodSolver, MisuseIsInvalidInput) {
  const LinearSystem s =
      backward_euler_system(3, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  const LinearSystem other =
      backward_euler_system(4, 1400, 1.0 / 60, DefinitenessFix::kClampCompressed);
  CholmodSolver cholmod;
  EXPECT_EQ(cholmod.factorize(s.a).status, LinearStatus::kInvalidInput);  // before analyze
  EXPECT_EQ(cholmod.analyze(SparseMatrix(3, 4)).status, LinearStatus::kInvalidInput);
  ASSERT_TRUE(cholmod.analyze(s.a).ok());
  EXPECT_EQ(cholmod.factorize(other.a).status, LinearStatus::kInvalidInput);  // other pattern
  ASSERT_TRUE(cholmod.factorize(s.a).ok());
  VecX short_x = VecX::Zero(3);
  EXPECT_EQ(cholmod.solve(s.b, short_x).status, LinearStatus::kInvalidInput);
}

}  // namespace
}  // namespace jelly
