#pragma once
// Preconditioned conjugate gradients behind the LinearSolver interface, preconditioned by the
// inverse diagonal (Jacobi), by a CHOLMOD factor of an earlier matrix ("lagged"), which is
// refreshed only when CG needs more than a few iterations with it or after invalidate(), or by
// a smoothed-aggregation algebraic multigrid cycle
// (solvers/linear/detail/smoothed_aggregation.hpp).
#include <functional>
#include <memory>
#include <vector>

#include <jelly/solvers/linear/detail/cholmod_solver.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

// kJacobi inverts the 3x3 diagonal blocks (block Jacobi) when the matrix has the 3x3-block
// pattern of a SpringJacobian, and the scalar diagonal otherwise.
// kAmg: one V-cycle of smoothed aggregation per iteration; needs the 3x3-block pattern.
enum class CgPreconditioner { kJacobi, kLaggedCholesky, kAmg };

struct CgOptions {
  CgPreconditioner preconditioner = CgPreconditioner::kJacobi;
  Real tolerance = 1e-8;  // stop when |b - A x| <= tolerance |b|
  int max_iterations = 1000;
  // Amg: the coarse levels' values are refreshed at the next factorize when a solve took more
  // than refactor_iterations iterations (1: every factorize) or after invalidate(); the
  // aggregates are built once per pattern.
  // Lagged Cholesky: the factor is refreshed at the next factorize when the CPU time of the last
  // solve exceeded the average cost per solve (factorization included) since the last refresh,
  // which minimises the average cost, or when a solve took more than this many iterations.
  int refactor_iterations = 20;
  // Lagged Cholesky: when a solve with an old factor has not converged after this many
  // iterations, refactor at once and solve again.
  int lagged_iteration_limit = 30;
  // Amg: the Chebyshev smoothers' degrees on level 0 and on the coarse levels, and whether
  // levels below 1 are visited twice (a W-cycle).
  int amg_fine_degree = 2;
  int amg_coarse_degree = 4;
  bool amg_w_cycle = true;
  CholmodOptions cholmod;
};

class CgSolver final : public LinearSolver {
 public:
  explicit CgSolver(CgOptions options = {});
  ~CgSolver() override;

  // "cg_jacobi", "cg_lagged_cholmod" or "cg_amg".
  std::string_view name() const override;
  LinearResult analyze(const SparseMatrix& a) override;
  LinearResult factorize(const SparseMatrix& a) override;
  LinearResult solve(const VecX& b, VecX& x) override;
  void invalidate() override;
  // Threads of the mat-vec, the preconditioner and the vector operations (results do not
  // depend on it: fixed partitions and sums in fixed chunks, docs/threads.md).
  void set_threads(int threads) override;
  // The CHOLMOD factorizations done for the lagged preconditioner (counted in counters() too),
  // or the multigrid hierarchies built or refreshed.
  long preconditioner_factorizations() const;
  // Amg: the positions of the particles (3 per particle) whose rigid-body modes are the near-null
  // space of the next hierarchy built (without them: the translations only).
  void set_coordinates(const VecX& x);
  // Amg: whether the next factorize builds a hierarchy (and so reads the coordinates).
  bool needs_coordinates() const;
  // Amg: the levels of the hierarchy (0 before the first factorize).
  int multigrid_levels() const;

 private:
  struct Impl;  // the preconditioner, the upper block triangle of A, the CG vectors
  std::unique_ptr<Impl> impl_;
};

// Conjugate gradients on an operator given as a product function (matrix-free, e.g.
// core/detail/band_system.hpp), preconditioned by the inverses of its 3x3 diagonal blocks (block
// Jacobi, as CgSolver's); threaded as CgSolver (the same bits for any thread count).
class MatrixFreeCg {
 public:
  using Product = std::function<void(const VecX& in, VecX& out)>;
  // Writes the row-major 3x3 diagonal block of particle i of A into out.
  using DiagonalBlock = std::function<void(int i, Real out[9])>;
  MatrixFreeCg();
  ~MatrixFreeCg();
  // The preconditioner of the next solves: inverts the diagonal blocks of `particles` particles.
  // A singular block or one with a non-positive diagonal entry is a kNotPositiveDefinite failure
  // naming the first such block. No allocation once called with this size and thread count.
  LinearResult set_diagonal_blocks(int particles, const DiagonalBlock& block, int threads);
  // Solves A x = b from x with A x = apply(x), preconditioned by the last set_diagonal_blocks.
  // Stops at |b - A x| <= tolerance |b|. With `resume`, continues the last solve (which must
  // have converged, with the same b, x as it left it, A and preconditioner) to this tolerance:
  // the iterates are those of one solve to this tolerance, at max_iterations more.
  LinearResult solve(const Product& apply, const VecX& b, VecX& x, Real tolerance,
                     int max_iterations, int threads, bool resume = false);
  // The same, preconditioned by z = precondition(r) instead (a fixed symmetric positive
  // definite operator, e.g. a multigrid V-cycle; threaded by the caller); set_diagonal_blocks
  // is not needed. A resumed solve restarts the search direction from its residual.
  using Preconditioner = std::function<void(const VecX& r, VecX& z)>;
  LinearResult solve(const Product& apply, const Preconditioner& precondition, const VecX& b,
                     VecX& x, Real tolerance, int max_iterations, int threads, bool resume = false);
  const LinearSolverCounters& counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace jelly
