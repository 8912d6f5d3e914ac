#pragma once
// Body-body and self contact inside the implicit Euler solve (docs/contact.md, "Body contact
// inside the implicit solve").
//
// Every pair of particles that may touch during the step (the broad phase of BodyContact, each
// radius grown by the distance the particle can travel in the step) is a candidate. Its geometry
// is linearized at the start of the step: n = (x_j0 - x_i0) / |x_j0 - x_i0|, and the gap at the
// end of the step is g1 = |x_j0 - x_i0| - (r_i + r_j) + h n.(w0 + dw), w = v_j - v_i (a
// separating plane: the true distance is never smaller than g1 + r_i + r_j). An active pair is a
// stiff one-sided spring on that gap and a friction on the relative tangential velocity, both
// implicit in the step, so that their Jacobian blocks enter the backward-Euler matrix:
//   impulse on j (on i the opposite) = -h k g1 n - c P_t (w0 + dw),  P_t = I - n n^T,
//   k = kappa m_ij / h^2 (m_ij the pair's reduced mass), so that h^2 k = kappa m_ij: the step
//   ends with 1 / (1 + kappa) of a lone pair's predicted overlap; a resting load F compresses
//   the contact by F h^2 / (kappa m_ij);
//   c = kappa m_ij while the pair sticks (the relative tangential velocity drops to 1 / (1 +
//   kappa) of the free one), c = mu p_n / |w1_t| while it slides (an implicit viscosity that
//   gives the friction mu p_n at the current speed and never reverses the sliding, lagged by one
//   solve as for the terrains).
// The matrix gains the blocks +H at (i, i) and (j, j), -H at (i, j) and (j, i), H = h^2 k n n^T
// + c P_t: symmetric positive semi-definite, so the matrix stays SPD for every linear solver.
// The pattern of the (i, j) blocks is the integrator's business (ImplicitEuler keeps the union
// of the candidates in its SpringJacobian, re-analysing only when a new pair appears).
// Active set, as for the terrains: a candidate whose end gap the solve makes overlap by more than
// 0.1 % of r_i + r_j becomes active (a shallower overlap is left to the next step's prediction), an
// active pair whose spring would pull (g1 > 0) is released, solving again while that changes. Stick
// -> slide when the tangential impulse leaves the cone mu_s p_n; slide -> stick when the viscosity
// reaches 100 m_ij. All impulses are equal and opposite (linear momentum is conserved exactly by an
// exact solve) and act along the start-of-step line of centres or across it: the normal ones change
// no angular momentum (backward Euler changes L by sum x0 x impulse), friction does. Restitution
// after the solve: a pair that approached faster than the resting speed at the start of the step
// and is in contact at its end gets e times that approach along its end-of-step line of centres (no
// torque), scaled down if needed so that the total energy does not grow over the step. Before that,
// a safety net: an overlap deeper than 0.5 % of r_i + r_j at the end of the step (the pair springs'
// compliance under a whole body's momentum at a landing at 1/30 s) is projected back to 0.5 % along
// the line of centres, with the angular momentum of the projection's lever taken back (as
// BodyContact::resolve does).
#include <utility>
#include <vector>

#include <jelly/core/detail/sparse_matrix.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>

namespace jelly {

class ImplicitBodyContact {
 public:
  enum class Mode { kStick, kSlide };

  struct Pair {
    int i = 0, j = 0;             // particles, i < j
    Vec3 normal = Vec3::UnitY();  // from x_i0 to x_j0
    Real reach = 0;               // r_i + r_j
    Real gap0 = 0;                // |x_j0 - x_i0| - reach
    Real mass = 0;                // reduced mass (a pinned partner is infinitely heavy)
    Real approach = 0;            // -(w0 . n) at the start of the step
    bool active = false;
    bool release = false;  // held for this step (pulled without a new solve), free at the next
    Mode mode = Mode::kStick;
    Real viscosity = 0;  // sliding friction c
    Real kappa = 0;      // h^2 k = kappa mass (kStiffness; kept per pair for a later policy)
  };

  struct Counters {
    long extra_solves = 0;         // solves caused by changes of the active pairs
    long not_converged = 0;        // steps that ended with the active pairs still changing
    long restitution_limited = 0;  // steps whose bounce the energy bound reduced
    long projected = 0;            // overlaps deeper than 0.5 % projected after the solve
  };

  // The relative stiffness kappa (h^2 k = kappa m_ij).
  static constexpr Real kStiffness = 1000;

  // Starts a step of size h from s0 with forces f(x0, v0): the candidate pairs and the active
  // set (last step's active pairs that the explicit prediction x0 + h (v0 + h f / m) keeps
  // touching, and the pairs it makes overlap). Returns whether there is a candidate.
  bool begin_step(const Model& model, BodyContact& contact, const State& s0, const VecX& f, Real h);
  const std::vector<Pair>& pairs() const { return pairs_; }
  bool any_active() const { return active_ > 0; }

  // Adds the active pairs' blocks to `a` (full storage, 3x3 blocks; the pattern must hold the
  // (i, j) blocks of every candidate) and, if b is not null, their constant impulses to b.
  void add_terms(SparseMatrix& a, VecX* b) const;
  // w -= the active pairs' impulses at the end velocities v1 (a Newton residual).
  void subtract_impulses(const VecX& v1, VecX& w) const;
  // After a solve (dv = v1 - v0): the impulses, friction and next active set. Returns true when
  // the set changes; the new set replaces the old only with `commit`.
  bool update(const VecX& dv, bool commit);
  // Ends the step s1 (x1 = x0 + h v1): restitution within the energy the step lost (from the
  // step's start; the energies on up to `threads` threads), statistics into `contact`.
  void finish(const Model& model, State& s1, BodyContact& contact, int threads);

  // The active pairs' (i, j, mode, viscosity, kappa), appended to `out`, and back (restore
  // throws InputError for values no save could have written).
  void save(std::vector<Real>& out) const;
  void restore(const Real* data, size_t size);
  static constexpr size_t kSavedPerPair = 5;
  size_t saved_size() const;

  const Counters& counters() const { return counters_; }

 private:
  // The pair's coupling block H and its impulse on j at relative velocity w0 + dw with dw = 0.
  Eigen::Matrix3d block(const Pair& p) const;
  Vec3 impulse(const Pair& p, const Vec3& w1) const;
  Real stick_viscosity(const Pair& p) const { return kStiffness * p.mass; }

  Real h_ = 0;
  const Model* model_ = nullptr;
  BodyContactParams params_;
  VecX x0_, v0_, pad_;
  std::vector<Pair> pairs_;
  int active_ = 0;
  // The last step's active pairs (sorted by (i, j)) with their friction state.
  struct Carried {
    int i, j;
    Mode mode;
    Real viscosity;
    Real kappa;
  };
  std::vector<Carried> carried_;
  std::vector<BroadPhase::Pair> resolved_;
  VecX bounce_;
  double seconds_ = 0;
  Counters counters_;
};

}  // namespace jelly
