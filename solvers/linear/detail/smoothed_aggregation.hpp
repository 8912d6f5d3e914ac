#pragma once
// An algebraic multigrid preconditioner by smoothed aggregation (Vanek, Mandel and Brezina 1996,
// as PETSc's GAMG builds it) for the assembled implicit step's CG on any body: tet meshes,
// cloth, voxelized and mixed scenes (docs/implicit.md, "Algebraic multigrid").
//
// Level 0 is the matrix as CG sees it (3x3 blocks of particles, contact rows and pins already
// filtered: S A S + I - S). Aggregates of nodes are built once per pattern from the pattern's
// node graph (greedy: a node with all neighbours free seeds an aggregate of itself and them;
// the rest join a neighbouring aggregate or form their own). The tentative prolongator T holds
// on each aggregate an orthonormal basis of the near-null space: on level 0 the 6 rigid-body
// modes about the aggregate's centre from the coordinates given (3 translations only without
// them), on coarse levels the coarse representation of the finer level's modes; a rank-deficient
// aggregate (2 nodes, collinear nodes) keeps the modes its nodes can carry. A node whose
// off-diagonal blocks are all zero at setup (a pin, a sticking contact) is left out of T.
//
// Values: P = (I - 4/(3 lambda) D^-1 A) T (lambda: a power-iteration estimate of the largest
// eigenvalue of D^-1 A), coarse operators P^T A P symmetrized, the coarsest solved by a dense
// Cholesky factor. refresh() recomputes them from the current values; between refreshes the
// coarse levels lag while level 0's smoother and residuals use the current matrix.
//
// Smoother: a Chebyshev polynomial in D^-1 A (D the diagonal blocks), of degree 2 on level 0
// and 4 on the coarse levels, on [upper / 10, upper], upper = 1.1 times the power estimate (at
// most 2 on level 0, where lambda_max(D^-1 A) <= 2 for a mass plus positive semi-definite
// spring blocks); the same polynomial before and after the coarse correction, and levels below
// 1 visited twice (a W-cycle): the cycle is symmetric positive definite whatever coarse
// operators it holds. Every loop of the cycle is a gather over rows on a static split and the
// setup is serial: the same bits for any thread count.
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>

#include <jelly/core/detail/sparse_matrix.hpp>
#include <jelly/core/types.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class SmoothedAggregation {
 public:
  // The cycle: Chebyshev degrees and whether levels below 1 are visited twice (W-cycle).
  struct Options {
    int fine_degree = 2;
    int coarse_degree = 4;
    bool w_cycle = true;
  };
  SmoothedAggregation() = default;
  explicit SmoothedAggregation(Options options) : options_(options) {}

  // Aggregates and tentative prolongators for the pattern of `a` (full storage, symmetric, 3x3
  // blocks of particles, compressed) and the values of refresh(a). `coordinates` (3 per
  // particle, or empty) give the rotations of the near-null space. Allocates: once per pattern.
  LinearResult setup(const SparseMatrix& a, const VecX& coordinates, int threads);
  // The smoothed prolongators, coarse operators and smoothers from the values of `a` (the
  // pattern of setup). Allocates.
  LinearResult refresh(const SparseMatrix& a, int threads);
  // Level 0's smoother from the values of `a` (the matrix of the next apply()); no allocation.
  LinearResult update_fine(const SparseMatrix& a, int threads);
  // z = B r: one V-cycle from zero on the matrix of the last update_fine / refresh.
  void apply(const VecX& r, VecX& z, int threads);

  bool ready() const { return !levels_.empty(); }
  void clear() { levels_.clear(); }
  int levels() const { return static_cast<int>(levels_.size()); }
  // Unknowns and stored entries of level l.
  int unknowns(int l) const { return levels_[l].rows(); }
  long non_zeros(int l) const;

 private:
  using RowMatrix = Eigen::SparseMatrix<Real, Eigen::RowMajor, int>;
  // A CSR view of a level's matrix: level 0 is the caller's (symmetric, so its compressed
  // columns are its rows), the others are owned.
  struct View {
    int rows = 0;
    const int* ptr = nullptr;
    const int* col = nullptr;
    const Real* val = nullptr;
  };
  struct Level {
    RowMatrix a;                  // coarse levels (level 0: the caller's matrix, fine_)
    std::vector<int> node_start;  // [nodes + 1]: first unknown of each node
    std::vector<Real> inverse;    // the inverses of the diagonal blocks, row-major, packed
    std::vector<int> inverse_start;
    Real upper = 2;  // the smoother's bound on the eigenvalues of D^-1 A
    // Transfers to the next coarser level (absent on the coarsest).
    RowMatrix tentative, p, r;
    std::vector<int> aggregate;  // [nodes]: aggregate of each node (-1: none)
    int aggregates = 0;
    std::vector<int> coarse_start;  // [aggregates + 1]: first coarse unknown of each aggregate
    VecX x, b, t, d, w, s;          // the cycle's vectors
    int rows() const { return node_start.empty() ? 0 : node_start.back(); }
    int nodes() const { return static_cast<int>(node_start.size()) - 1; }
  };

  View view(int l) const;
  // Aggregates of level l's node graph (pattern only).
  void aggregate(int l);
  // Level l's tentative prolongator from the near-null space `modes` (rows x m, row-major);
  // writes the coarse level's modes and its node sizes.
  void tentative(int l, const std::vector<Real>& modes, int m, std::vector<Real>& coarse_modes);
  // Inverts level l's diagonal blocks; fails naming a block that is not positive definite.
  LinearResult invert_diagonal(int l, int threads);
  // The largest eigenvalue of D^-1 A on level l, by power iteration from a fixed vector.
  Real estimate_lambda(int l, int threads);
  void multiply(int l, const VecX& x, VecX& y, int threads) const;
  // out = alpha out + beta D^-1 res (alpha 0: out is not read).
  void scale_add(int l, const VecX& res, VecX& out, Real alpha, Real beta, int threads) const;
  // t = b - A x on level l.
  void residual(int l, const VecX& x, int threads);
  // The smoother on level l's b, from x (or from zero).
  void relax(int l, VecX& x, bool from_zero, int threads);
  void transfer(const RowMatrix& m, const VecX& in, VecX& out, bool add, int threads) const;
  void cycle(int l, int threads);

  Options options_;
  const SparseMatrix* fine_ = nullptr;
  std::vector<Level> levels_;
  Eigen::LLT<Eigen::MatrixXd> coarsest_;
  bool coarsest_dense_ = false;
  std::vector<char> isolated_;  // [fine nodes]: all off-diagonal blocks zero at setup
};

}  // namespace jelly
