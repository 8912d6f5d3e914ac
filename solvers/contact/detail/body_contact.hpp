#pragma once
// Contact between bodies, and within a body (docs/contact.md, "Body-body and self contact").
// Particles are spheres of their body's contact radius. After every step (for every integrator,
// after the terrains' contact) a broad phase (a spatial hash, linear in the number of particles)
// finds the pairs closer than the sum of their radii: pairs of different bodies, and with
// self-contact pairs of one body that no spring joins. The pairs are resolved with equal and
// opposite impulses, all pairs of a pass from one state (Jacobi: no pair sees another's result
// within a pass, so mirrored inputs give mirrored results and the order of the pairs does not
// matter), each particle's mass shared among its pairs (mass splitting):
//  1. velocity passes: the approach along the line of centres is absorbed or, above a resting
//     speed, reflected with at most the given restitution, and Coulomb friction bounded by mu
//     times the normal impulse slows the sliding. Split, each pass is a set of separate
//     two-particle collisions followed by inelastic merges: it never adds kinetic energy;
//  2. projection passes: the overlap is taken out along the line of centres (weighted by
//     inverse mass). Moving a particle into its own body compresses the springs behind it
//     while the particles there keep their speed, which adds energy the collision never had
//     (docs/contact.md). So the projection is also computed as translations of whole bodies
//     (no spring changes length), and the state takes the particles' projection as far as the
//     total energy stays at or below the energy at the start of the step (bisection on a blend
//     of the two): an integrator that loses energy keeps losing it through the contact.
// Pinned particles count as infinitely heavy (and a body with pins is not translated). Linear
// momentum is conserved exactly; angular momentum is conserved exactly by the normal response
// and the projection (the projection's lever is taken back by the smallest tangential pair
// impulses), and changed by friction only (by the torque of a tangential impulse between two
// particle centres, which the particles cannot take up as spin).
#include <string>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/body_contact_params.hpp>
#include <jelly/solvers/contact/detail/broad_phase.hpp>

namespace jelly {

class BodyContact {
 public:
  struct Stats {
    long pairs = 0;    // contact pairs resolved, summed over the steps
    long limited = 0;  // steps whose projection was limited to keep the energy (translations)
    double broad_seconds = 0;   // time in the broad phase
    double narrow_seconds = 0;  // time filtering and resolving the pairs
    long steps = 0;
  };

  BodyContact() = default;
  explicit BodyContact(BodyContactParams params);

  const BodyContactParams& params() const { return params_; }
  // Whether resolve() can do anything for this model: two bodies, or a body with self-contact.
  bool active(const Model& model) const;
  // Resolves the contacts of `state` after a step of size h from `before`.
  void resolve(const Model& model, const State& before, State& state, Real h);
  // The pairs of the last resolve() (global particle indices, i < j).
  const std::vector<BroadPhase::Pair>& pairs() const { return contacts_; }
  const Stats& stats() const { return stats_; }

  // For an integrator that resolves body contact inside its step (implicit_euler,
  // solvers/contact/detail/implicit_body_contact.hpp): the filtered pairs (as resolve() keeps
  // them) whose spheres overlap at `x` when each radius r is grown to r (1 + margin) + pad[i]
  // (pad: the distance the particle may travel in the step). The time counts as broad phase.
  const std::vector<BroadPhase::Pair>& find_candidates(const Model& model, const VecX& x,
                                                       const VecX& pad, Real margin);
  // Ends a step whose contacts the integrator resolved: `pairs` in contact at its end (what
  // pairs() returns), `narrow_seconds` of the integrator's contact work.
  void record_step(const std::vector<BroadPhase::Pair>& pairs, double narrow_seconds);
  // Per particle (after find_candidates() on the model): contact radius, inverse mass (0 for
  // pins).
  Real radius(int i) const { return radius_[i]; }
  Real inverse_mass(int i) const { return inverse_mass_[i]; }

  // Throws InputError naming both bodies when two bodies' particles overlap in `x` (closer than
  // their radii sum less `tolerance` relative), and for self-contact two particles of one body
  // that no spring joins.
  void check_no_overlap(const Model& model, const VecX& x, Real tolerance = 1e-9);

 private:
  // Per-particle radius, inverse mass (0 for pins), body index, and the springs' neighbour lists,
  // made once per model.
  void prepare(const Model& model);
  // Keeps the broad phase's pairs that may touch: other bodies, or (self-contact) no spring.
  void filter(const Model& model);
  bool joined(int i, int j) const;
  // resolve()'s passes: the velocity passes (returns whether a pair approached), and the
  // projection of the overlaps at state.x into particle moves (moved_) and into body
  // translations plus the self-contact pairs' particle moves (shifted_).
  bool velocity_passes(const State& before, State& state, Real h);
  void projection_passes(const Model& model, const VecX& x);
  // The state for the blend `share` (1: the particles' projection, 0: the translations) from
  // x, v: positions x + blend, velocities v with the projection's lever taken back.
  void blend(const Model& model, Real share, const VecX& x, const VecX& v, State& out);

  BodyContactParams params_;
  BroadPhase broad_;
  const Model* prepared_for_ = nullptr;
  int prepared_particles_ = -1, prepared_springs_ = -1;
  VecX radius_, inverse_mass_, padded_;
  std::vector<int> body_;
  std::vector<int> neighbour_start_, neighbours_;  // CSR, sorted
  std::vector<BroadPhase::Pair> candidates_, contacts_;
  Stats stats_;
  // resolve()'s work arrays (sized once per model).
  std::vector<int> share_;               // [N] pairs of a particle in this pass
  std::vector<Vec3> impulse_, back_;     // [pairs]
  std::vector<char> touching_;           // [pairs]
  VecX moved_, shifted_;                 // [3N]
  std::vector<Vec3> body_shift_;         // [bodies]
  std::vector<Real> body_inverse_mass_;  // [bodies] 0 with a pin
  std::vector<int> body_share_;          // [bodies]
  State start_;                          // after the velocity passes
};

}  // namespace jelly
