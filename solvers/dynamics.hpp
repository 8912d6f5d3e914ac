#pragma once
// The right-hand side every integrator sees: the model's forces (gravity, springs, dampers,
// external forces at time t) plus the contact forces active during the current step and the
// anchor springs (external pulls), and the accelerations M^-1 f, with pinned particles following
// their paths. With a seed_framework terrain, an evaluation also runs the course framework's
// collision handler on its own state (stage_acceleration()).
// Public as what an integrator of one's own evaluates (docs/extending.md): forces(),
// acceleration(), stage_acceleration(), added_force_jacobians(), model(), threads(). The
// Simulator constructs it; the accessors of contact and the force loop's bands return types of
// internal headers, for jelly's own methods.
#include <jelly/core/force.hpp>
#include <jelly/core/model.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

class SpringBands;    // core/detail/spring_bands.hpp: the Simulator's vectorised force loop
class BodyContact;    // solvers/contact/detail/body_contact.hpp
class ContactSolver;  // solvers/contact/detail/contact_solver.hpp

class Dynamics {
 public:
  // `terrains` (may be null) is for integrators that resolve contact inside their step;
  // `bands` (may be null), built for `model`, evaluates the spring forces faster; `anchors`
  // (may be null) are added to the forces, and implicit integrators add their Jacobian;
  // `threads` (>= 1) is how many threads the force loop and the integrators' own loops may use;
  // `body_contact` (may be null: no contact between bodies) is for integrators that resolve it
  // inside their step (Integrator::resolves_body_contact()); `extra_forces` (may be null):
  // forces added to the model's at every evaluation (Force plugins, core/force.hpp).
  Dynamics(const Model& model, const ContactSolver& contacts, const Terrains* terrains = nullptr,
           const SpringBands* bands = nullptr, const AnchorSprings* anchors = nullptr,
           int threads = 1, BodyContact* body_contact = nullptr,
           const ForceList* extra_forces = nullptr);

  // f(t, x, v): size 3N, no allocation. Pinned particles get the forces as if free (an
  // implicit method constrains them itself).
  void forces(Real t, const VecX& x, const VecX& v, VecX& f) const;
  // f += the forces applied from outside the springs: the model's external forces and the
  // added Force plugins (not gravity, the springs or contact). For methods that treat these
  // explicitly while they handle the springs themselves (xpbd).
  void add_applied_forces(Real t, const VecX& x, const VecX& v, VecX& f) const;
  // The Jacobian blocks at (t, x, v) of the added forces that give them (Force::has_jacobian())
  // into `out` (cleared first; no allocation in steady state). Throws InputError naming the
  // force for a block out of range or not finite.
  void added_force_jacobians(Real t, const VecX& x, const VecX& v, ForceJacobian& out) const;
  // a = M^-1 f(t, x, v), except that pinned particles get their path's acceleration.
  void acceleration(Real t, const VecX& x, const VecX& v, VecX& a) const;
  // The evaluation of an explicit method's stage at time t (docs/contact.md, seed_framework):
  // a as acceleration(t, x, v, a), with the seed_framework terrains' collision handler run on
  // (x, v, f) before the division by the masses; it reflects v in place. The integrator uses
  // that reflected v as the stage's dx/dt, and the first stage's evaluation changes the step's
  // own velocity, as in the framework. Without seed_framework terrains the same as
  // acceleration(t, x, v, a), v unchanged.
  void stage_acceleration(Real t, const VecX& x, VecX& v, VecX& a) const;
  // True when a terrain uses seed_framework: the integrator must evaluate through
  // stage_acceleration() (integrator_supports_in_evaluation_contact()).
  bool has_in_evaluation_contact() const { return in_evaluation_contact_; }

  // The model.
  const Model& model() const { return *model_; }
  // The terrain contact of the step.
  const ContactSolver& contacts() const { return *contacts_; }
  // The terrains of the scene, or null.
  const Terrains* terrains() const { return terrains_; }
  // The vectorised force loop's bands (core/detail/spring_bands.hpp), or null.
  const SpringBands* bands() const { return bands_; }
  // The contact between bodies (and within a body) the Simulator resolves after the step unless
  // the integrator resolves it inside; null when there is none.
  BodyContact* body_contact() const { return body_contact_; }
  // The anchor springs, or null when there are none.
  const AnchorSprings* anchors() const { return anchors_; }
  // The added Force plugins, or null when there are none.
  const ForceList* added_forces() const { return forces_; }
  // Force evaluations so far.
  long force_evaluations() const { return evaluations_; }
  // Threads the integrator may use for its own loops (results do not depend on it).
  int threads() const { return threads_; }

 private:
  // True when the forces are the bands' (gravity, springs, dampers) and the seed contact terms:
  // no anchors, external or added forces.
  bool springs_and_seed_contacts_only() const;

  const Model* model_;
  const ContactSolver* contacts_;
  const Terrains* terrains_;
  const SpringBands* bands_;
  const AnchorSprings* anchors_;
  int threads_;
  BodyContact* body_contact_;
  const ForceList* forces_;
  bool in_evaluation_contact_;
  mutable long evaluations_ = 0;
};

}  // namespace jelly
