#pragma once
// Internal (not installed). Coulomb contact for the position-based integrators
// (projective_dynamics, xpbd; docs/realtime.md): particles are kept on the coulomb terrains'
// surfaces (their thickness above them, detail/thickness.hpp) by projection at the end of the
// (sub)step t1, with Coulomb friction, and bounce after it with restitution, within the energy the
// step lost. Two ways to use it:
//  * projective dynamics (constrain_residual + project, per iteration): the inward normal part of
//    a contact's residual r = f - M (v1 - v0) / h is the contact force (it is removed before the
//    global solve, so the fixed point balances every force exactly); a sticking contact's whole
//    residual is taken while it lies in the static cone |r_t| <= mu_s r_n, a sliding one gets the
//    kinetic friction mu r_n against its sliding;
//  * xpbd (project_with_friction, per substep): position-based friction (Macklin et al. 2014):
//    the tangential displacement relative to the surface is undone when it is within mu_s times
//    the normal correction, else reduced by mu times it.
// Each (sub)step: begin(), the iterations, then finish() on the new state.
#include <cstdint>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/detail/restitution.hpp>

namespace jelly {

class PositionContact {
 public:
  enum class Mode : std::uint8_t { kFree, kNew, kStick, kSlide };

  struct Counters {
    long restitution_limited = 0;  // (sub)steps whose bounce the energy budget reduced
  };

  // Starts a (sub)step of size h from s0, ending at t1 = s0.t + h. The contacts of the last one
  // are forgotten, or, with keep_contacts (projective dynamics), kept with their mode: a
  // sliding contact goes on sliding, and the residual releases those that lift off. Returns
  // false when no terrain uses the coulomb model (nothing to do).
  bool begin(const Model& model, const Terrains& terrains, const State& s0, Real h,
             bool keep_contacts = false);

  // Projective dynamics, before the global solve, at the iterate x with residual r (3N): takes
  // the contact forces out of r, releases contacts whose residual pulls them off, decides stick
  // or slide and adds the kinetic friction of sliding contacts. No allocation.
  void constrain_residual(const VecX& x, VecX& r);
  // Projective dynamics: while frozen, contacts keep their mode (no release, no change between
  // stick and slide; new contacts still start) and sliding ones their friction force, so that
  // the last iterations of a step converge for a fixed set instead of cycling between sets.
  // begin() unfreezes.
  void freeze(bool frozen) { frozen_ = frozen; }
  // Projective dynamics, after the global solve: a particle below a coulomb surface at t1
  // becomes a contact, every contact is put on its surface, a sticking one at its anchor (its
  // start position moved with the surface). A sliding contact whose slip reversed sticks.
  void project(VecX& x);
  // XPBD: the particles below a coulomb surface at t1 are put on it, with position-based
  // friction against their displacement since x0 relative to the surface.
  void project_with_friction(VecX& x);

  // Ends the (sub)step at s1 (t1, v1 = (x1 - x0) / h): contacts stop moving into their surface,
  // and those that approached it faster than its resting_speed at the start bounce with its
  // restitution, scaled down so that the energy (kinetic + elastic + gravitational, in the
  // surface's frame) does not exceed the energy at the start (computed on up to `threads`
  // threads).
  void finish(const Model& model, State& s1, int threads);

  // Particles in contact (after project / finish), and which.
  int count() const { return static_cast<int>(active_.size()); }
  const std::vector<int>& active() const { return active_; }
  Mode mode(int particle) const { return slot_[particle].mode; }
  // The surface normal of a contact.
  const Vec3& normal(int particle) const { return slot_[particle].normal; }
  const Counters& counters() const { return counters_; }

 private:
  struct Slot {
    Mode mode = Mode::kFree;
    int terrain = -1;
    Vec3 normal = Vec3::UnitY();
    Vec3 surface_velocity = Vec3::Zero();
    Vec3 slip_direction = Vec3::Zero();  // sliding: unit direction the friction opposes
    Real normal_correction = 0;          // xpbd: total projection depth of this substep
    Real friction_used = 0;              // xpbd: tangential correction of this substep
    Vec3 friction = Vec3::Zero();        // sliding: the friction force of the last iteration
  };
  // The coulomb terrain whose surface, offset by `gap` (the particle's thickness), p penetrates
  // deepest at t1, and its signed distance to that offset surface; -1 if none.
  int deepest(const Vec3& p, Real gap, Real* distance) const;
  void activate(int i, int terrain, const Vec3& p);
  // The sticking position of particle i: its start position moved with the surface, on it (its
  // thickness above it).
  Vec3 anchor(int i) const;

  const Model* model_ = nullptr;
  const Terrains* terrains_ = nullptr;
  std::vector<int> coulomb_;  // indices of the coulomb terrains
  Real t1_ = 0, h_ = 0;
  bool frozen_ = false;
  VecX x0_, v0_;
  VecX gap_;                 // [N]: each particle's thickness (detail/thickness.hpp)
  std::vector<Slot> slot_;   // [N]
  std::vector<int> active_;  // particles whose mode is not kFree
  std::vector<Bounce> bounces_;
  Counters counters_;
};

}  // namespace jelly
