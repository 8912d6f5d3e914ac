#pragma once
// Internal to arkode_dirk (not part of the public API): the Newton systems of ARKStep,
// (I - gamma J) [dx; dv] = [bx; bv] with J = [[0, I], [M^-1 K, M^-1 D]], K = df/dx, D = df/dv
// of the springs, solved by the Schur reduction to the SPD
//   S dv = M bv + gamma K bx,  S = M - gamma D - gamma^2 K,  dx = bx + gamma dv,
// as a custom SUNLinearSolver that holds its own matrices (matrix-free for ARKODE).
#include <memory>
#include <string>

#include <Eigen/SparseCore>

#include <jelly/core/model.hpp>
#include <jelly/solvers/arkode_support.hpp>

namespace jelly::arkode {

using SparseMatrix = Eigen::SparseMatrix<Real>;  // column-major (CSC), compressed

// The spring Jacobians K, D on one fixed pattern (every 3x3 block a spring touches, and the
// whole diagonal) and the Cholesky factorization of S = M - gamma D - gamma^2 K, whose symbolic
// analysis is done once per pattern.
class SchurSystem {
 public:
  explicit SchurSystem(const Model& model);
  ~SchurSystem();
  SchurSystem(const SchurSystem&) = delete;
  SchurSystem& operator=(const SchurSystem&) = delete;

  // Refills K and D at (x, v). The geometric term of compressed springs is clamped to zero
  // (Choi and Ko 2002) and the damper's position derivative left out, so that both stay
  // symmetric negative semi-definite: a Newton matrix, not the exact Jacobian.
  void assemble(const Model& model, const VecX& x, const VecX& v);
  // Factorizes S = M - gamma D - gamma^2 K; false, with the reason, unless S is positive
  // definite.
  bool factorize(const Model& model, Real gamma, std::string* why);
  // out = S^-1 r with the last factorization.
  void solve(const VecX& r, VecX& out) const;

  const SparseMatrix& k() const { return k_; }
  const SparseMatrix& d() const { return d_; }
  Eigen::Index size() const { return k_.rows(); }

 private:
  struct Factorization;
  SparseMatrix k_, d_, s_;
  // For spring i, offsets into the value arrays of its 4 blocks, column-major within a block:
  // blocks (a, a), (b, b), (a, b), (b, a), 9 entries each.
  std::vector<int> scatter_;
  std::vector<int> diagonal_;  // offset of entry (j, j) for every column j
  std::unique_ptr<Factorization> factorization_;
};

// The custom linear solver. `arkode_memory` is the ARKStep memory (for gamma and the state to
// linearize about), `data` the right-hand side data (for the model).
struct SchurStatistics {
  long factorizations = 0, not_positive_definite = 0, solves = 0;
};
LinearSolverPtr make_schur_solver(SUNContext context, void* arkode_memory, const RhsData* data);
// ARKStepSetLinearSolver with no matrix, keeping ARKODE's calls to setup(); a SUNDIALS flag.
int attach_schur_solver(void* arkode_memory, SUNLinearSolver solver);
const SchurStatistics& schur_statistics(SUNLinearSolver solver);

}  // namespace jelly::arkode
