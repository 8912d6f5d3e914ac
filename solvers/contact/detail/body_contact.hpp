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
//     of the two): an integrator that loses energy keeps losing it through the contact. The
//     particles' projection whole is checked on the whole model; a bisected blend's energy is
//     the energy after the velocity passes plus what the blend changes: the kinetic energy of
//     the pairs' particles, the springs of those particles and between bodies (a translation
//     changes no spring within a body) and gravity's (linear in the blend).
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
    long pairs = 0;     // contact pairs resolved, summed over the steps
    long limited = 0;   // steps whose projection was limited to keep the energy (translations)
    long collided = 0;  // steps whose pairs came from collide()'s set
    long searched = 0;  // steps that searched again (no collide(), or a particle beyond its reach)
    double broad_seconds = 0;   // time in the broad phase
    double narrow_seconds = 0;  // time filtering and resolving the pairs
    long steps = 0;
  };

  BodyContact() = default;
  explicit BodyContact(BodyContactParams params);

  const BodyContactParams& params() const { return params_; }
  // Whether resolve() can do anything for this model: two bodies, or a body with self-contact.
  bool active(const Model& model) const;
  // The collision phase of a step, before the integrator moves anything (as Warp's collide()
  // before simulate()): the pairs that may touch during a step of size h from `state`, each
  // particle's sphere grown by its reach (a share of its radius, and the distance its velocity
  // and gravity carry it in the step). The step's consumer takes its pairs from this set:
  // resolve() when every particle ended within its reach, find_candidates() when its pads fit
  // within the reaches; otherwise it searches again. Both give the same pairs in the same
  // (sorted) order, so results never depend on the reach, only the cost does; the set serves
  // one step (the state it was found for) once.
  void collide(const Model& model, const State& state, Real h);
  // The pairs of the last collide() (filtered as resolve() filters, i < j).
  const std::vector<BroadPhase::Pair>& collisions() const { return collisions_; }
  // Resolves the contacts of `state` after a step of size h from `before`.
  void resolve(const Model& model, const State& before, State& state, Real h);
  // The pairs of the last resolve() (global particle indices, i < j, sorted).
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
  // Whether collide()'s set was found at exactly `x` and not used yet; marks it used.
  bool take_collisions(const VecX& x);
  // contacts_ = the pairs of collide()'s set whose spheres, of radius radius_[i] + pad[i]
  // (pad may be null), overlap at `x`.
  void select_collisions(const VecX& x, const VecX* pad);
  bool joined(int i, int j) const;
  // resolve()'s passes: the velocity passes (returns whether a pair approached), and the
  // projection of the overlaps at state.x into particle moves (moved_) and into body
  // translations plus the self-contact pairs' particle moves (shifted_).
  bool velocity_passes(const State& before, State& state, Real h);
  void projection_passes(const Model& model, const VecX& x);
  // The state for the blend `share` (1: the particles' projection, 0: the translations) from
  // start_: positions x + blend, velocities v with the projection's lever taken back.
  void blend(const Model& model, Real share, State& out);
  // What blend_energy_change() needs, once per resolve: the angular momentum and gravitational
  // energy of the two projections (linear in the share), the pairs' particles and the springs
  // they touch (with the springs between bodies), each spring's and pair's vector as a line in
  // the share, and their part of start_'s energy.
  void prepare_blend(const Model& model);
  // The multiplier mu of the tangential impulses mu x d_p that take back the projection's
  // angular momentum dl, d_p = pair_d_[p] the pairs' vectors (zero when there is none).
  Vec3 lever_multiplier(const Vec3& dl) const;
  // The total energy of blend(share) less the energy of start_, summed over the pairs' particles
  // and springs only.
  Real blend_energy_change(const Model& model, Real share);

  BodyContactParams params_;
  BroadPhase broad_;
  const Model* prepared_for_ = nullptr;
  int prepared_particles_ = -1, prepared_springs_ = -1;
  VecX radius_, inverse_mass_, padded_;
  std::vector<int> body_;
  std::vector<int> neighbour_start_, neighbours_;  // CSR, sorted
  std::vector<int> spring_start_, springs_of_;     // CSR: the springs of each particle
  std::vector<int> cross_springs_;                 // springs joining two bodies (or none)
  std::vector<BroadPhase::Pair> candidates_, contacts_;
  // collide()'s set: its pairs, the position it was found at, each particle's reach.
  std::vector<BroadPhase::Pair> collisions_;
  VecX collided_x_, reach_;
  bool collisions_fresh_ = false;
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
  // prepare_blend()'s results and blend_energy_change()'s work arrays.
  struct BlendLine {  // a vector at the share s: at_start + s by_particles + (1 - s) by_bodies
    Vec3 at_start, by_particles, by_bodies;
    Vec3 at(Real s) const { return at_start + s * by_particles + (1 - s) * by_bodies; }
  };
  std::vector<int> blend_particles_, blend_springs_;  // the pairs' particles, their springs
  std::vector<char> particle_mark_, spring_mark_;     // [N], [springs] all 0 between resolves
  std::vector<BlendLine> pair_lines_, spring_lines_;  // [pairs] x_j - x_i, [blend_springs_]
  std::vector<Vec3> pair_d_;                          // [pairs] x_j - x_i at one share
  VecX blend_v_;                                      // [3N] velocities of blend_particles_
  Vec3 lever_moved_, lever_shifted_;                  // sum m dx x v of moved_, shifted_
  Real gravity_moved_ = 0, gravity_shifted_ = 0;      // -sum m g . dx of moved_, shifted_
  Real blend_start_energy_ = 0;  // start_'s kinetic and elastic energy of the pairs' part
};

}  // namespace jelly
