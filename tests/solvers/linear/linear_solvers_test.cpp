// Every backend of the LinearSolver interface on the same systems.
#include <gtest/gtest.h>

#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/solvers/linear/detail/cholmod_solver.hpp>
#include <jelly/solvers/linear/detail/ldlt_solver.hpp>

#include "solvers/linear/linear_systems.hpp"

namespace jelly {
namespace {

using testing::backward_euler_system;
using testing::LinearSystem;
using testing::solve_with;

// Every backend, and every CHOLMOD ordering, solves the same SPD system to 1e-10 relative.
TEST(LinearSolvers, BackendsAgreeOnTheSameSystem) {
  for (Real ks : {1400.0, 100000.0}) {
    const LinearSystem s =
        backward_euler_system(5, ks, 1.0 / 60, DefinitenessFix::kClampCompressed);
    CholmodSolver reference;
    const VecX x = solve_with(reference, s.a, s.b);
    EXPECT_LT((s.a * x - s.b).norm(), 1e-13 * s.b.norm());
    for (CholmodOrdering o :
         {CholmodOrdering::kAmd, CholmodOrdering::kNesdis, CholmodOrdering::kBest}) {
      CholmodOptions options;
      options.ordering = o;
      options.supernodal_min_rows = o == CholmodOrdering::kAmd ? 1 << 30 : 0;  // both paths
      CholmodSolver solver(options);
      EXPECT_LT((solve_with(solver, s.a, s.b) - x).norm(), 1e-10 * x.norm())
          << cholmod_ordering_name(o);
    }
    LdltSolver ldlt;
    EXPECT_LT((solve_with(ldlt, s.a, s.b) - x).norm(), 1e-10 * x.norm());
    CgOptions cg;
    cg.tolerance = 1e-14;
    CgSolver jacobi(cg);
    EXPECT_LT((solve_with(jacobi, s.a, s.b) - x).norm(), 1e-10 * x.norm());
    cg.preconditioner = CgPreconditioner::kLaggedCholesky;
    CgSolver lagged(cg);
    EXPECT_LT((solve_with(lagged, s.a, s.b) - x).norm(), 1e-10 * x.norm());
  }
}

// A crushed jelly without a definiteness fix: every backend reports "not positive definite"
// instead of returning garbage; with the default fix the same state is fine.
TEST(LinearSolvers, NotPositiveDefiniteIsAStatus) {
  const LinearSystem s = backward_euler_system(4, 100000, 1.0 / 30, DefinitenessFix::kNone, 0.4);
  VecX x = VecX::Zero(s.b.size());
  CholmodSolver cholmod;
  LdltSolver ldlt;
  CgSolver cg;
  for (LinearSolver* solver : std::initializer_list<LinearSolver*>{&cholmod, &ldlt, &cg}) {
    ASSERT_TRUE(solver->analyze(s.a).ok()) << solver->name();
    LinearResult r = solver->factorize(s.a);
    if (r.ok()) r = solver->solve(s.b, x);  // CG finds it in its iterations
    EXPECT_EQ(r.status, LinearStatus::kNotPositiveDefinite) << solver->name() << ": " << r.message;
  }
  const LinearSystem fixed =
      backward_euler_system(4, 100000, 1.0 / 30, DefinitenessFix::kClampCompressed, 0.4);
  for (LinearSolver* solver : std::initializer_list<LinearSolver*>{&cholmod, &ldlt, &cg}) {
    ASSERT_TRUE(solver->factorize(fixed.a).ok()) << solver->name();
    EXPECT_TRUE(solver->solve(fixed.b, x).ok()) << solver->name();
  }
}

}  // namespace
}  // namespace jelly
