#pragma once
// The spring forces of a lattice in a loop that vectorises: springs grouped into bands by their
// index offset b - a (the cube of build_cube has 16 offsets: 1, n, n^2, n +- 1, ...), each band
// stored densely over a range of first particles, with positions, velocities and forces
// transposed to one array per coordinate. Within a band the loop reads particles a and a + offset
// from contiguous memory, so the compiler vectorises sqrt, division and all (AVX2 where the CPU
// has it, chosen at run time); docs/performance.md has its measurements.
// Slots of a band that are not springs have zero coefficients.
//
// Same forces as compute_forces up to rounding (another summation order). A model whose springs
// do not fill their bands densely, or a state with a degenerate (collapsed) spring, is evaluated
// by compute_forces instead. With threads, each thread owns a range of particles; it computes
// the forces of the slots that touch its particles (the slots at the boundary of two ranges are
// computed by both) and adds them in the serial loop's order (docs/threads.md).
#include <vector>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/model.hpp>

namespace jelly {

class SpringBands {
 public:
  // Springs (a, b = a + offset) with a = first + slot, for slot in [0, spring.size()).
  struct Band {
    int offset = 0;                  // b - a
    int first = 0;                   // first particle a of slot 0
    std::vector<int> spring;         // [slots]: spring index, or -1
    std::vector<Real> rest, ks, kd;  // [slots]: 0 where no spring
    // True when every spring of the band has the same ks and kd (and a rest length > 0): the
    // force loop then reads uniform_ks and uniform_kd instead of the arrays.
    bool uniform = false;
    Real uniform_ks = 0, uniform_kd = 0;
    int slots() const { return static_cast<int>(spring.size()); }

    // For a thread that owns the particles [p0, p1): the slots [lo, hi) whose first particle
    // (a = first + slot) or second (b = a + offset) is one of its own, and among them the
    // particles a0..a1 that are the first ends of slots lo + (a0 - first - lo) ... and b0..b1
    // the second ends of slots lo + (b0 - first - offset - lo) ... (empty ranges when lo >= hi).
    struct Reach {
      int lo, hi, a0, a1, b0, b1;
    };
    Reach reach(int p0, int p1) const;
  };

  SpringBands() = default;
  // Groups the springs of `model` (allocates; once per model).
  explicit SpringBands(const Model& model);

  // Whether the bands hold every spring of the model (else compute_forces does the work).
  bool dense() const { return dense_; }
  // True when built for a model with these particle and spring counts.
  bool fits(const Model& model) const;
  const std::vector<Band>& bands() const { return bands_; }
  int max_offset() const { return max_offset_; }

  // f = m g + spring and damper forces at (x, v), as compute_forces, on up to `threads`
  // threads; the same bits for any thread count (each thread owns a range of particles and
  // adds their terms in the one order of the serial loop). No allocation once called with
  // this thread count. Not for concurrent calls on one object (it keeps its scratch arrays).
  void compute_forces(const Model& model, const VecX& x, const VecX& v, VecX& f,
                      int threads = 1) const;
  // Terms a caller adds to the forces of a range of particles, each particle's on its own
  // (the seed contact forces): called by each thread of the force loop for its own particles.
  class RangeTerms {
   public:
    // Adds the terms of the particles [begin, end) to f (size 3N, the springs' sums there).
    virtual void add(int begin, int end, VecX& f) const = 0;

   protected:
    ~RangeTerms() = default;
  };

  // a = M^-1 (f + terms) with f as compute_forces and `terms` (may be null) added to f, each
  // thread adding and dividing the sums it made (no pass or thread team of their own); the same
  // bits as compute_forces, then terms->add(0, N, f), then a = f * (1 / m).
  void compute_accelerations(const Model& model, const VecX& x, const VecX& v, VecX& a,
                             int threads = 1, const RangeTerms* terms = nullptr) const;

 private:
  // compute_forces, or compute_accelerations (with `terms`) when `accelerations`.
  void evaluate(const Model& model, const VecX& x, const VecX& v, VecX& f, int threads,
                bool accelerations, const RangeTerms* terms) const;
  // Copies rest lengths, ks and kd from the model into the bands.
  void copy_coefficients(const Model& model);

  std::vector<Band> bands_;
  int particles_ = 0;
  int springs_ = 0;
  int max_offset_ = 0;
  bool dense_ = false;
  // Per thread of the last call's team: the copies of x and v within its slots' reach, the band
  // forces of its slots, the sums of its particles, and its count of collapsed springs.
  struct Workspace {
    std::vector<Real> data;
    int collapsed = 0;
  };
  mutable std::vector<Workspace> workspaces_;
  mutable parallel::BalancedSplit split_;  // the particles of each thread
};

}  // namespace jelly
