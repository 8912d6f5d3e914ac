#pragma once
// The backward-Euler matrix A = M - alpha D - beta K of a lattice without an assembled sparse
// matrix: per spring slot of the force loop's bands (core/detail/spring_bands.hpp) its 3x3 block
// B = -alpha D_k - beta K_k = c1 u u^T + c2 I (u the spring's unit direction) as two numbers,
// c1 / |e|^2 and c2 with e = x_a - x_b recomputed from the positions kept at assembly, and
// products A p = M p + sum over springs of +-B (p_a - p_b) computed band by band like the
// force loop (vectorised, threaded by particle ranges: the same bits for any thread count).
// 16 bytes per spring (8 in single precision) instead of about 220 for the full compressed-column
// matrix (docs/implicit.md, "Matrix-free CG").
#include <vector>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/force.hpp>
#include <jelly/core/model.hpp>

namespace jelly {

// A filter of the product at some particles (implicit_euler's contact filter), with S =
// map[slot[i]] where slot[i] >= 0 (slot: one entry per particle; map: 3x3, column-major):
//   input:  p_i -> S p_i, applied while the input is copied (no extra pass);
//   output (when `scale` is set, one number c per slot): y_i -> S y_i + c S p_i + (p_i - S p_i)
//           with p_i the unfiltered input, applied as the product writes its rows (no extra pass).
// `map` and `scale` are read only where `slot` is set; the output filter needs the input filter
// (S p_i is the filtered input), and the product's input and output must be distinct vectors.
struct ProductFilter {
  const int* slot = nullptr;
  const Real* map = nullptr;    // 9 numbers per slot
  const Real* scale = nullptr;  // 1 number per slot, or null: the input filter only
};

class BandSystem {
 public:
  BandSystem() = default;
  // For the springs of `bands` (dense, built for a model of `num_particles` particles); keeps a
  // pointer to `bands`, which must outlive this object. Allocates. With `single_precision` the
  // two coefficients per spring are stored as floats (8 bytes per spring instead of 16: faster
  // products where memory traffic bounds them); A is then exact to their rounding, 6e-8
  // relative per spring (and still symmetric), for iterative solves to tolerances well above
  // that.
  BandSystem(const SpringBands& bands, int num_particles, bool single_precision = false);
  bool single_precision() const { return single_; }

  bool built_for(const SpringBands& bands) const { return bands_ == &bands; }
  int rows() const { return 3 * num_particles_; }

  // A = M - alpha D - beta K at (x, v), K and D as SpringJacobian assembles them with the
  // definiteness fix (without the damper's non-symmetric term), and kw = K w. Returns false
  // when a spring has collapsed (shorter than kDegenerateLength times its rest length; its
  // direction is then undefined here: use SpringJacobian). No allocation after the first call
  // with this thread count.
  bool assemble(const Model& model, const VecX& x, const VecX& v, DefinitenessFix fix, Real alpha,
                Real beta, const VecX& w, VecX& kw, int threads);
  // A_pp += value I (anchors, wind drag). Call after assemble.
  void add_diagonal(int particle, Real value);
  // A += the symmetric part of -(alpha df/dv + beta df/dx) for the blocks of `jacobian` (added
  // forces' Jacobians, which lie off the bands): a block B at (i, j) puts B / 2 at (i, j) and
  // B^T / 2 at (j, i). Kept row by row, so that products, rows and diagonal blocks add them as
  // their own rows are computed (the same bits for any thread count). Replaces the blocks of
  // the last call; assemble() forgets them. No allocation in steady state.
  void set_extra_blocks(const ForceJacobian& jacobian, Real alpha, Real beta);
  bool has_extra_blocks() const { return !extra_column_.empty(); }
  // y = A p, or y = A p filtered by `filter` (when its slot is not null). No allocation after
  // the first call with this thread count.
  void multiply(const VecX& p, VecX& y, int threads, ProductFilter filter = {}) const;
  // assemble() and multiply() compute their rows in blocks of this many particles (every band
  // for one block, then the next: what a block reads stays in the cache); set from the bands'
  // largest offset. Any block size gives the same bits (a block's rows are computed as a
  // thread's range is).
  int row_block() const { return block_; }
  void set_row_block(int particles) { block_ = particles > 0 ? particles : 1; }
  // The rows of y = A p at the given particles only (distinct; the other rows of y are left as
  // they are): the same bits as multiply's without a filter, for a few particles (the
  // contacts' impulses) instead of a whole product; split between up to `threads` threads when
  // there are enough of them.
  void multiply_rows(const VecX& p, const std::vector<int>& particles, VecX& y,
                     int threads = 1) const;
  // The diagonal 3x3 block of particle i, row-major.
  void diagonal_block(int i, Real out[9]) const;
  // For operators built from A's pieces (the multigrid's coarse levels): the bands it was built
  // for, the mass term of particle i (m_i plus add_diagonal's values: A_ii = that I + the
  // springs' blocks), and the block B of slot `slot` of band `band` as 6 numbers (xx, yy, zz,
  // xy, xz, yz; zero for an empty slot), exactly the block the products use.
  const SpringBands& bands() const { return *bands_; }
  Real mass_term(int i) const { return mass_[i]; }
  void slot_block(size_t band, int slot, Real out[6]) const;

 private:
  struct Slots {
    std::vector<Real> e1, c2;                 // [slots]: c1 / |x_a - x_b|^2 and c2
    std::vector<float> e1_single, c2_single;  // the same, rounded (single precision)
  };
  // The threads of a pass over the slots, with band_ sized for them.
  int team(int threads) const;

  const SpringBands* bands_ = nullptr;
  int num_particles_ = 0;
  bool single_ = false;
  long slots_total_ = 0;         // slots of all bands
  size_t stride_ = 0;            // per-thread buffer length: N + the largest offset
  int block_ = 0;                // rows per block of assemble() and multiply()
  std::vector<Slots> slots_;     // per band
  std::vector<Real> mass_;       // [N] m + the diagonal additions
  std::vector<Real> diagonal_;   // [6N] xx, yy, zz, xy, xz, yz of the spring part of A_ii
  std::vector<Real> positions_;  // [3N] x, y, z of the particles at the last assembly
  // set_extra_blocks(): per particle row i, the entries extra_start_[i] .. extra_start_[i + 1]
  // of column extra_column_[e] and 3x3 value extra_value_[9 e ..] (row-major).
  std::vector<int> extra_start_, extra_column_, extra_fill_;
  std::vector<Real> extra_value_;
  // Scratch: SoA copies of the inputs, accumulators, and per thread its slots' terms.
  mutable std::vector<Real> scratch_;
  mutable std::vector<Real> band_;
  mutable std::vector<int> collapsed_;
  mutable parallel::BalancedSplit split_;  // multiply's particles of each thread
};

}  // namespace jelly
