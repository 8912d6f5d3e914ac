#pragma once
// Coulomb contact inside the implicit Euler solve (docs/implicit.md, "Contact inside the solve").
//
// A particle that the step would carry into a coulomb terrain becomes a velocity constraint of
// the linear system: its normal velocity is prescribed so that it ends the step on the surface
// (n.v1 = -d(x0, t1) / h, d the distance to the surface less the particle's thickness,
// detail/thickness.hpp), and, while it sticks, its tangential velocity is the surface's. The
// system is filtered as in Baraff & Witkin 1998 (section 5.3): with S_i the projector onto the
// free directions of particle i, the solve is (S A S + C + I - S) y = S (b - C w0 - A z),
// dv = y + z, with z the prescribed components and C the sliding friction (below); this keeps
// A's sparsity pattern and its definiteness, so every linear solver works unchanged. The
// constraint impulse p_i = (A dv - b)_i then decides which particles touch, solving again while
// that changes (at most contact_iterations solves):
//   free -> contact  when the solve carries the particle below the surface;
//   contact -> free  when p_n < 0 (the surface would have to pull); a particle whose
//                    prescribed normal velocity is >= 0 (touching, not landing) is pulled
//                    without work, so it is held for this step and let go at the next,
//                    without another solve.
// Friction follows each solve, for the next solve or step (a change of friction alone is no
// reason to solve again):
//   stick -> slide   when |p_t| > mu_s p_n (outside Coulomb's cone);
//   slide            friction is an implicit tangential viscosity c_i, impulse -c_i (v1 - u)_t
//                    (C = c_i P_t on the diagonal block), with c_i = mu p_n / |(v1 - u)_t| from
//                    the last solve: it always opposes the sliding and never reverses it;
//   slide -> stick   when c_i reaches 100 m_i (the particle has all but stopped).
// A new contact sticks or slides as a lone particle would (|v_t| <= mu_s dv_n sticks).
// The constraint impulses do no positive work (p_n >= 0 against a velocity that lands the
// particle; friction against the sliding), so contact adds no energy to the backward-Euler step.
// Pinned particles (Model::pins) are constraints of the same kind with all three directions
// prescribed: their velocity at the end of the step is their path's (S_i = 0); they are never
// released and take no part in friction or restitution.
// At the end of the step a contact's normal velocity relative to the surface is zeroed, and a
// particle that hit the surface faster than the resting speed bounces with restitution e, as far
// as the energy the step lost allows (in the terrain's frame); a lone particle bounces fully.
#include <vector>

#include <Eigen/SparseCore>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/detail/restitution.hpp>

namespace jelly {

class ImplicitContact {
 public:
  enum class Mode { kStick, kSlide };

  struct Contact {
    int particle = 0;
    int terrain = 0;
    Mode mode = Mode::kStick;
    Vec3 normal = Vec3::UnitY();
    Vec3 surface_velocity = Vec3::Zero();
    Real target_normal = 0;  // n.v1 that lands the particle on the surface at t1
    // Sliding: friction impulse -viscosity (v1 - u)_t, implicit in the solve, with
    // viscosity = mu p_n / |(v1 - u)_t| iterated; always against the sliding.
    Real viscosity = 0;
    Real normal_impulse = 0;      // p_n of the last solve
    Vec3 impulse = Vec3::Zero();  // p of the last solve (the adjoint's friction path)
    bool release = false;         // held for this step (pulled without work), free at the next
    Real approach = 0;            // -(v0 - u).n at the start of the step
    bool pinned = false;          // a pinned particle: v1 = target_velocity, terrain -1
    Vec3 target_velocity = Vec3::Zero();
  };

  struct Counters {
    long extra_solves = 0;         // solves beyond the first caused by active-set changes
    long not_converged = 0;        // steps that ended with the active set still changing
    long restitution_limited = 0;  // steps whose bounce the energy budget reduced
  };

  // Starts a step of size h from s0 (time s0.t) with forces f(x0, v0): the model's pinned
  // particles, then the last step's contacts still touching their terrain and the particles that
  // the explicit prediction x0 + h (v0 + h f / m) puts below a coulomb terrain. Returns whether
  // there is anything to constrain: pins, or a terrain that uses the coulomb model. The
  // searches over all particles (here and in the updates of this step) run on `threads`.
  bool begin_step(const Model& model, const Terrains& terrains, const State& s0, const VecX& f,
                  Real h, int threads = 1);
  bool has_constraints() const { return !contacts_.empty(); }

  // Filters a (full storage, 3x3 blocks, symmetric) in place to S A S + C + I - S after saving
  // the columns of the constrained particles, and forms rhs and z: with `prescribe` (the
  // linearized solves of a step) z = the prescribed velocity changes and rhs = S (b - C w0 - A z),
  // else (Newton corrections, whose b includes the friction) z = 0 and rhs = S b. Projects
  // `guess` (an initial iterate) onto the free directions.
  void constrain(SparseMatrix& a, const VecX& b, bool prescribe, VecX& rhs, VecX& z, VecX& guess);
  // Puts the saved columns back (before constraining again with another active set).
  void unconstrain(SparseMatrix& a) const;
  // After a solve of the filtered system a (dv = y + z; b as passed to constrain): the contacts'
  // impulses and the next active set. Returns true when the set changes; then, if `commit`, a is
  // unconstrained and the new set replaces the old (solve again), else nothing changes.
  bool update(const Terrains& terrains, const VecX& b, const VecX& dv, bool commit,
              SparseMatrix& a);
  // Matrix-free counterparts (A given only by products, core/detail/band_system.hpp); the
  // filtered operator is y = S A (S p) + C p + (I - S) p:
  //   constrain_rhs: as constrain without touching a matrix; `a_z` must be A z for the z this
  //     call returns in `z` -- it is called twice: first with a_z = null (computes z; returns
  //     whether z is non-zero), then with A z (forms rhs and projects guess).
  bool constrain_rhs(const VecX& b, bool prescribe, const VecX* a_z, VecX& rhs, VecX& z,
                     VecX& guess);
  //   product_filter: the filter for BandSystem::multiply (valid until the contacts change):
  //     the product's input q = p with q_c = S_c p_c at the contacts (q = p elsewhere), and its
  //     output y_c = S_c y_c + C_c p_c + (I - S_c) p_c at the contacts, for y = A q.
  ProductFilter product_filter();
  //   the filtered diagonal block S D S + C + I - S of a contact particle (D row-major, in
  //     place), for block Jacobi; returns false for a particle without contact.
  bool filter_diagonal_block(int particle, Real block[9]) const;
  //   update from the product a_dv = A dv with the original A (no matrix to unconstrain; only
  //     its rows at the contacts' particles are read). With `screening` (dv from a loose solve
  //     that is finished only if the set holds) a set that holds is left as it was: the
  //     impulses and friction modes come from the finished solve, as without screening.
  bool update_from_product(const Terrains& terrains, const VecX& b, const VecX& dv, bool commit,
                           const VecX& a_dv, bool screening = false);
  // S applied in place to a 3N vector (a Newton residual).
  void project(VecX& w) const;
  // w += c_i (v1 - u)_t: removes the sliding friction impulses at velocities v1 from w.
  void subtract_friction(const VecX& v1, VecX& w) const;
  // Ends the step (s1 = x0 + h v1, v1; time t1): zeroes the contacts' normal velocity relative to
  // the surface, projects onto the surface any particle left below it, and applies restitution
  // within the energy budget (add_bounded_bounces; its energies on up to `threads` threads).
  void finish(const Model& model, const Terrains& terrains, State& s1, int threads);

  // The contact set as numbers (what begin_step() carries over: particle, terrain, mode,
  // viscosity, release per contact), appended to `out`; and back (InputError when malformed).
  void save(std::vector<Real>& out) const;
  void restore(const Real* data, size_t size);

  // Particles in contact with a terrain at the end of the last step (pins not counted).
  int count() const { return static_cast<int>(contacts_.size()) - pinned_ + projected_; }
  const std::vector<Contact>& contacts() const { return contacts_; }
  const Counters& counters() const { return counters_; }

 private:
  // The projector onto the free directions of a contact.
  static Eigen::Matrix3d free_projector(const Contact& c);
  // The filtered diagonal block S D S + c S + I - S of contact c's particle (c the sliding
  // friction's viscosity on the tangent plane, 0 for a sticking or pinned contact).
  static Eigen::Matrix3d filtered_diagonal(const Contact& c, const Eigen::Matrix3d& d);
  // z_c: the velocity change the contact prescribes from v0 (all of it for a pin or a sticking
  // contact, the normal part for a sliding one).
  Vec3 prescribed_change(const Contact& c) const;
  // rhs_c -= c (v0 - u)_t: the sliding friction's impulse at the start velocity (sliding
  // contacts only).
  void subtract_sliding_friction(const Contact& c, VecX& rhs) const;
  // e times the approach speed for a contact that hit its surface faster than the resting
  // speed (it bounces), else 0.
  static Real bounce_speed(const Contact& c, const Terrains& terrains);
  // Contact of particle i (mass m) with terrain k, from x0, v0 and the velocity v1 with which
  // the particle would end the step without it.
  Contact make_contact(const Terrains& terrains, int i, int k, const Vec3& v1, Real mass) const;
  void index_contacts();
  // update() with the constraint impulse of contact ci from impulse(ci, c) and the matrix put
  // back by unconstrain_matrix() when the set changes (`screening`: see update_from_product).
  template <class Impulse, class Unconstrain>
  bool update_impl(const Terrains& terrains, const VecX& dv, bool commit, bool screening,
                   Impulse&& impulse, Unconstrain&& unconstrain_matrix);
  // The coulomb terrain whose surface, offset by `gap` (the particle's thickness), position p (at
  // time t1) penetrates deepest by more than `tolerance`, or -1.
  int penetrated_terrain(const Terrains& terrains, const Vec3& p, Real gap, Real tolerance) const;
  // terrain_index_[k]: where last step's terrain k is now (-1: removed). Terrains removed
  // between steps shift the indices after them; one put in place of another
  // (Simulator::replace_terrain, a terrain not seen last step) keeps its index.
  void renumber_terrains(const Terrains& terrains);
  // penetrating_[i] = penetrated_terrain(terrains, position(i), tolerance) for the particles
  // without a contact (slot_[i] < 0; -1 for the others), on threads_.
  template <class Position>
  void find_penetrating(const Terrains& terrains, Position&& position, Real tolerance);

  Real t1_ = 0, h_ = 0;
  const Model* model_ = nullptr;  // of the current step
  VecX x0_, v0_;
  VecX gap_;  // [N]: each particle's thickness (detail/thickness.hpp), set by begin_step
  std::vector<Contact> contacts_, next_;
  std::vector<Bounce> bounces_;    // finish(): the contacts that bounce
  std::vector<int> slot_;          // [N]: index into contacts_ or -1
  std::vector<Real> projectors_;   // [9 * contacts]: S_c column-major (product_filter)
  std::vector<Real> viscosities_;  // [contacts]: C_c's viscosity, 0 unless sliding (product_filter)
  std::vector<char> pinned_mask_;  // [N]: pinned this step
  std::vector<Real> saved_;        // original values of the constrained columns
  std::vector<int> saved_at_;      // [contacts]: offset into saved_
  std::vector<int> penetrating_;   // [N]: find_penetrating's terrains
  // The terrains of the last begin_step() (empty after restore(): its indices hold) and
  // renumber_terrains()'s result.
  std::vector<const Terrain*> last_terrains_;
  std::vector<int> terrain_index_;
  int threads_ = 1;
  int projected_ = 0;
  int pinned_ = 0;  // the first pinned_ entries of contacts_ are pins
  Counters counters_;
};

}  // namespace jelly
