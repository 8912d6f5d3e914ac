#pragma once
// Sparse Jacobians df/dx (K) and df/dv (D) of the spring and damper forces on one fixed 3x3-block
// sparsity pattern, built once with a per-particle neighbour list; each assembly only refills the
// values, column by column (a gather: every column is written by one thread, in one order, so
// the values are the same bit for bit for any thread count; docs/threads.md).
#include <utility>
#include <vector>

#include <jelly/core/detail/sparse_matrix.hpp>
#include <jelly/core/force.hpp>
#include <jelly/core/model.hpp>

namespace jelly {

struct JacobianOptions {
  DefinitenessFix definiteness = DefinitenessFix::kClampCompressed;
  // The damper force -kd c u has a non-symmetric df/dx term -kd/L u (P w)^T, w = va - vb.
  // false (used by the solvers) drops it, so K is symmetric; true keeps it, so that with kNone K
  // is the exact df/dx (tests).
  bool exact_damper = false;
};

// Per spring k = (a, b) its 3x3 blocks df_a/dxa of K and df_a/dva of D at (x, v), row-major, 9
// values per spring (spring k at [9k, 9k + 9)), as assemble() computes them; the spring's other
// blocks are df_a/dxb = df_b/dxa = -df_a/dxa and df_b/dxb = df_a/dxa. For matrix-free products:
// (K p)_a += K_k (p_a - p_b), (K p)_b -= K_k (p_a - p_b). Resizes the vectors to 9M.
void spring_jacobian_blocks(const Model& model, const VecX& x, const VecX& v,
                            const JacobianOptions& options, std::vector<Real>& k_blocks,
                            std::vector<Real>& d_blocks);

class SpringJacobian {
 public:
  // Builds the pattern of the 3N x 3N matrices for the springs of `model`: one dense 3x3 block
  // per particle on the diagonal and per spring (a, b) at (a, b) and (b, a). Full storage (both
  // triangles), compressed column, sorted row indices.
  // `extra_blocks` (i, j) add the blocks (i, j) and (j, i) to the pattern, zero after every
  // assembly (for terms a caller adds itself, e.g. contact pairs between bodies).
  explicit SpringJacobian(const Model& model,
                          const std::vector<std::pair<int, int>>& extra_blocks = {});

  int rows() const { return 3 * num_particles_; }
  int non_zeros() const { return col_start_.back(); }
  int num_springs() const { return num_springs_; }
  // A matrix with this pattern and zero values (allocates; call once).
  SparseMatrix make_matrix() const;
  // True when `m` has this pattern's size (the matrices passed below must come from make_matrix).
  bool matches(const SparseMatrix& m) const;

  // K = df/dx and D = df/dv of the spring and damper forces at (x, v), on up to `threads`
  // threads. No allocation.
  void assemble(const Model& model, const VecX& x, const VecX& v, const JacobianOptions& options,
                SparseMatrix& k, SparseMatrix& d, int threads = 1) const;
  // The backward-Euler matrix A = M - alpha D - beta K and kw = K w, in one pass over the
  // columns (K as assembled with `options`, which must not set exact_damper), on up to
  // `threads` threads (each spring's blocks are computed for both of its columns). No
  // allocation.
  void assemble_system(const Model& model, const VecX& x, const VecX& v,
                       const JacobianOptions& options, Real alpha, Real beta, SparseMatrix& a,
                       const VecX& w, VecX& kw, int threads = 1) const;
  // Adds `value` to entry (dof, dof) of a matrix with this pattern (an external force's
  // diagonal Jacobian, core/force.hpp).
  void add_to_diagonal(SparseMatrix& m, int dof, Real value) const {
    m.valuePtr()[diagonal_[dof]] += value;
  }

 private:
  // Calls column(j) for the column particles j of a static split of [0, N) on up to `threads`.
  template <class Column>
  void for_columns(int threads, Column&& column) const;
  // Walks column j's row blocks but its own: spring(i, k) for every spring k joining j to the
  // block's particle i, then block(slot) once that block's springs are done (an extra block's
  // has none).
  template <class Spring, class Block>
  void for_column_springs(int j, Spring&& spring, Block&& block) const;

  int num_particles_ = 0;
  int num_springs_ = 0;
  std::vector<int> col_start_;      // [3N + 1]
  std::vector<int> column_stride_;  // [N]: distance between columns 3j and 3j + 1 of particle j
  std::vector<int> diagonal_;       // [3N]: value index of entry (i, i)
  // Per particle j, its springs sorted by the other particle i (then by spring):
  // neighbour_[e], spring_[e] for e in [adjacency_start_[j], adjacency_start_[j + 1]). The row
  // blocks of column j are its distinct neighbours and j itself (at self_slot_[j]), in order.
  std::vector<int> adjacency_start_;  // [N + 1]
  std::vector<int> neighbour_;        // [2M]
  std::vector<int> spring_;           // [2M]: the spring, or -1 for an extra block
  std::vector<int> self_slot_;        // [N]
};

}  // namespace jelly
