#pragma once
// Internal to arkode_dirk (not part of the public API): iterative solves of ARKStep's Newton
// systems (I - gamma J) [dx; dv] = [bx; bv], J = [[0, I], [M^-1 K, M^-1 D]], without sparse
// matrices or factorizations (docs/arkode.md, "Iterative Newton solves"):
//  * "cg": the Schur reduction S dv = M bv + gamma K bx, dx = bx + gamma dv (as "schur"), with
//    S = M - gamma D - gamma^2 K applied matrix-free from each spring's 3x3 blocks and solved by
//    conjugate gradients preconditioned with S's 3x3 diagonal blocks, to ARKODE's tolerance;
//  * "jacobi": the Newton matrix replaced by its block diagonal (per particle the 6x6 block,
//    by the same reduction): one pass over the particles per solve, a modified Newton whose
//    contraction per iteration is about |gamma D_offdiagonal| (small steps only);
//  * "gmres" (SUNDIALS' SPGMR on the 6N system) uses block_jacobi() as its preconditioner.
// Every solve uses ARKODE's current gamma: no refactorization, no refinement.
#include <string>
#include <vector>

#include <jelly/core/force.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/arkode/detail/arkode_support.hpp>

namespace jelly::arkode {

// K and D linearized at a state, kept as their springs' 3x3 blocks (core/jacobian: the default
// definiteness fix, the damper's non-symmetric term dropped, as the Schur solver's).
//
// Seed contacts: a particle in seed contact whose force pushes into the surface has the normal
// part of its force cancelled (docs/contact.md), so its row of J has no normal component and
// the Newton system prescribes its normal velocity change, n.dv_i = n.bv_i. The solves then
// work on the filtered SPD system (Baraff and Witkin 1998) (P S P + I - P) y = P (rhs - S z),
// dv = y + z, P = I - n n^T on those particles and I elsewhere, z_i = n (n.bv_i). Their
// friction -mu N v_t is a tangential damper of coefficient c = mu N: S_ii gains gamma c P
// (its dependence on N through the forces is left out: the Newton iteration absorbs it).
//
// Pinned particles follow their paths: their acceleration does not depend on the state, so
// their rows of J are [0, I; 0, 0] and the Newton system prescribes dv_i = bv_i. They are
// filtered the same way with P_i = 0 (z_i = bv_i). Wind drag adds -drag I to D's diagonal.
// Added forces' Jacobian blocks (Force::add_jacobian) add their symmetric parts to K and D, as
// implicit_euler takes them.
class SpringOperator {
 public:
  struct Constraint {
    int particle;
    Vec3 normal;
    Real damping;  // mu N of the friction -mu N v_t (N/(m/s))
  };
  // `anchors` (may be null): their diagonal Jacobians -k I, -c I are added; the wind drag of
  // the model's external forces active at time t: -drag I on D's diagonal; the model's pins
  // (always) as above.
  // `forces` (may be null): the added forces' Jacobian blocks at (t, x, v)
  // (Dynamics::added_force_jacobians), copied.
  void linearize(const Model& model, const VecX& x, const VecX& v,
                 const AnchorSprings* anchors = nullptr, Real t = 0,
                 const ForceJacobian* forces = nullptr);
  // The particles whose normal acceleration the seed contact cancels (see above); call after
  // linearize(), before set_gamma().
  void set_constraints(std::vector<Constraint> constraints);
  const std::vector<Constraint>& constraints() const { return constraints_; }
  bool ready() const { return ready_; }
  long linearizations() const { return linearizations_; }
  // Prepares S = M - gamma D - gamma^2 K (per-spring blocks, diagonal blocks and their
  // inverses); does nothing when gamma is that of the last call.
  void set_gamma(const Model& model, Real gamma);
  // out = S p (size 3N), for the last set_gamma (without the filter).
  void multiply_s(const Model& model, const VecX& p, VecX& out) const;
  // out = (P S P + I - P) y, the filtered operator (= S y without constraints or pins).
  void multiply_filtered(const Model& model, const VecX& y, VecX& out);
  // r = P r (the constrained particles' normal components and the pinned particles' removed).
  void filter(VecX& r) const;
  // True when some particle is filtered (seed constraints or pins).
  bool filters() const { return !constraints_.empty() || !pinned_.empty(); }
  // z = the prescribed velocity change: n (n.bv_i) for a seed constraint, bv_i for a pin, 0
  // elsewhere (`bv` size 3N).
  void prescribed(const Real* bv, VecX& z) const;
  // out = K p (size 3N).
  void multiply_k(const Model& model, const Real* p, VecX& out) const;
  // z = diag^-1 r with the 3x3 diagonal blocks of the filtered operator (size 3N).
  void precondition(const VecX& r, VecX& z) const;
  // z = P^-1 r (6N, [x; v], may alias) with P = I - gamma J_d, J_d = J with K, D replaced by
  // their diagonal blocks: dv_i = S_ii^-1 (m_i r_v,i + gamma K_ii r_x,i), dx_i = r_x,i + gamma
  // dv_i (filtered for the constraints). For the last set_gamma.
  void block_jacobi(const Model& model, const Real* r, Real* z) const;

 private:
  // Per spring u (3), a = ks - s and s of K = -a u u^T - s I, and kd of D = -kd u u^T.
  std::vector<Real> spring_;      // [6M]
  std::vector<Real> k_diagonal_;  // [9N] K's diagonal blocks
  std::vector<Real> d_diagonal_;  // [9N] D's diagonal blocks
  std::vector<Real> s_;           // [2M] S's per-spring block alpha u u^T + beta I
  std::vector<Real> s_inverse_;   // [9N] inverses of the filtered diagonal blocks
  std::vector<Constraint> constraints_;
  AnchorSprings anchors_;                  // copies of the anchors' particle, k and c
  std::vector<int> pinned_;                // the model's pinned particles
  std::vector<char> is_pinned_;            // [N]
  std::vector<int> dragged_;               // particles with wind drag at the linearization
  std::vector<Real> drag_;                 // their drag (N s/m)
  VecX damping_;                           // workspace of linearize()
  std::vector<int> constraint_of_;         // [N] index into constraints_, or -1
  std::vector<Real> k_blocks_, d_blocks_;  // workspace of linearize()
  ForceJacobian forces_;                   // the added forces' blocks at the linearization
  VecX filtered_;                          // workspace of multiply_filtered()
  Real gamma_ = -1;
  bool ready_ = false;
  long linearizations_ = 0;
};

struct IterativeStatistics {
  long setups = 0, solves = 0, iterations = 0, failures = 0;
};

enum class IterativeMode { kCg, kJacobi };

// The custom SUNLinearSolver for "cg" and "jacobi": it presents itself as iterative (ARKODE then
// passes its tolerance, and calls setup() by its usual rules through the no-op preconditioner of
// attach_schur_solver) and linearizes at ARKODE's current Newton iterate in setup().
LinearSolverPtr make_iterative_solver(SUNContext context, void* arkode_memory, const RhsData* data,
                                      IterativeMode mode);
const IterativeStatistics& iterative_statistics(SUNLinearSolver solver);

}  // namespace jelly::arkode
