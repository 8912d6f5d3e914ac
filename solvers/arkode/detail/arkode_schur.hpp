#pragma once
// Internal to arkode_dirk (not part of the public API): the Newton systems of ARKStep,
// (I - gamma J) [dx; dv] = [bx; bv] with J = [[0, I], [M^-1 K, M^-1 D]], K = df/dx, D = df/dv
// of the springs, solved by the Schur reduction to the SPD
//   S dv = M bv + gamma K bx,  S = M - gamma D - gamma^2 K,  dx = bx + gamma dv,
// as a custom SUNLinearSolver that holds its own matrices (matrix-free for ARKODE).
#include <memory>
#include <string>

#include <jelly/core/detail/anchor_jacobian.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/arkode/detail/arkode_support.hpp>
#include <jelly/solvers/linear/detail/cholmod_solver.hpp>

namespace jelly::arkode {

// The spring Jacobians K, D (core/jacobian: one fixed pattern, every diagonal block present)
// and the CHOLMOD factorization of S = M - gamma D - gamma^2 K, analysed once per pattern.
class SchurSystem {
 public:
  // Below this many unknowns, a simplicial AMD factorization (measured in docs/arkode.md).
  static constexpr int kSupernodalFromDofs = 1000;

  explicit SchurSystem(const Model& model);
  ~SchurSystem();
  SchurSystem(const SchurSystem&) = delete;
  SchurSystem& operator=(const SchurSystem&) = delete;

  // Refills K and D at (x, v) with the default definiteness fix (compressed springs' geometric
  // term clamped, Choi and Ko 2002) and without the damper's non-symmetric df/dx term: a
  // symmetric Newton matrix, not the exact Jacobian. `anchors` (may be null): their diagonal
  // K and D are added.
  void assemble(const Model& model, const VecX& x, const VecX& v,
                const AnchorSprings* anchors = nullptr);
  // Factorizes S = M - gamma D - gamma^2 K (CHOLMOD's status and reason on failure:
  // kNotPositiveDefinite, kOutOfMemory, ...).
  LinearResult factorize(const Model& model, Real gamma);
  // out = S^-1 r with the last factorization; false with the reason on failure.
  bool solve(const VecX& r, VecX& out, std::string* why);

  const SparseMatrix& k() const { return k_; }
  const SparseMatrix& d() const { return d_; }
  Eigen::Index size() const { return k_.rows(); }
  const LinearSolverCounters& counters() const { return cholmod_.counters(); }

 private:
  SpringJacobian jacobian_;
  SparseMatrix k_, d_, s_;
  std::vector<int> diagonal_;  // value index of entry (j, j) for every column j
  CholmodSolver cholmod_;
  bool analysed_ = false;
};

// The custom linear solver. `arkode_memory` is the ARKStep memory (for gamma and the state to
// linearize about), `data` the right-hand side data (for the model).
struct SchurStatistics {
  long factorizations = 0, not_positive_definite = 0, solves = 0, refinements = 0;
};
LinearSolverPtr make_schur_solver(SUNContext context, void* arkode_memory, const RhsData* data);
// ARKStepSetLinearSolver with no matrix, keeping ARKODE's calls to setup(); a SUNDIALS flag.
int attach_schur_solver(void* arkode_memory, SUNLinearSolver solver);
const SchurStatistics& schur_statistics(SUNLinearSolver solver);
// CHOLMOD's reason for the last failed factorization or solve ("" if none).
const std::string& schur_error(SUNLinearSolver solver);

}  // namespace jelly::arkode
