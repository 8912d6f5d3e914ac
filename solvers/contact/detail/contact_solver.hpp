#pragma once
// Contact between particles and terrains, the same for every integrator (docs/contact.md): each
// terrain's contact model (solvers/contact/terrain_contact_model.hpp: coulomb, seed,
// seed_framework) answers
//  1. after each integrator step: resolve() applies each terrain's model to the new state
//     (velocity impulses, projections); an integrator that held a model's contact inside its
//     solve (coulomb in implicit_euler, xpbd, projective_dynamics) has resolve() skip it;
//  2. during the next step, every force evaluation calls add_forces(), which applies the contact
//     and friction forces of the contacts the models carried (the seed model's);
//  3. inside every force evaluation, for the models that act there (seed_framework:
//     apply_in_evaluation(), which the explicit integrators call through
//     Dynamics::stage_acceleration()).
#include <memory>
#include <string>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

class ContactSolver {
 public:
  // A contact carried into the next step (the seed model's): it gets the contact and friction
  // forces during that step.
  using SeedContact = CarriedContact;

  // Which terrains resolve() answers: all, or only those whose model the integrator did not
  // hold inside its step (TerrainContactModel::constrains_solves() false).
  enum class Scope { kAll, kUnsolvedOnly };

  // Applies every terrain's contact response to `state` (time state.t) after a step of size h
  // from the state `before`, on up to `threads` threads (each particle's response is its own;
  // the seed contacts are listed in particle order for any thread count).
  void resolve(const Model& model, const Terrains& terrains, const State& before, State& state,
               Real h, Scope scope = Scope::kAll, int threads = 1);
  // Adds contacts resolved elsewhere (inside an implicit step) to contact_count().
  void add_resolved(int count) { contact_count_ += count; }
  // For each contact carried from the last resolve() whose force f pushes into the surface,
  // cancels the inward normal force N and adds the friction -mu N v_t.
  void add_forces(const VecX& v, VecX& f) const;
  // add_forces for the particles in [begin, end) alone (each particle's terms in the same order).
  void add_forces(const VecX& v, VecX& f, int begin, int end) const;

  // The models that act inside a force evaluation (seed_framework), at time t on that
  // evaluation's own state (x, v) with its forces f (gravity, springs, dampers): terrains in
  // order, each seeing the forces the ones before added (TerrainContactModel::apply_in_evaluation).
  static void apply_in_evaluation(const Model& model, const Terrains& terrains, Real t,
                                  const VecX& x, VecX& v, VecX& f);
  // True when a terrain's model acts inside force evaluations.
  static bool has_in_evaluation_contact(const Terrains& terrains);

  // Particle-terrain contacts found by the last resolve() (seed_framework: the particles within
  // epsilon and approaching, which the next step's first evaluation will reflect).
  int contact_count() const { return contact_count_; }
  // Forget the seed contacts (after a restart or a state set from outside).
  void clear();

  // The seed contacts of the last resolve(), and their restoration (checkpoint restart).
  const std::vector<SeedContact>& seed_contacts() const { return seed_contacts_; }
  void restore(std::vector<SeedContact> seed_contacts, int contact_count);

 private:
  std::vector<SeedContact> seed_contacts_;
  int contact_count_ = 0;
  // Per thread of resolve(): its contacts and seed contacts, merged in range order.
  std::vector<std::vector<SeedContact>> part_seed_;
  std::vector<int> part_count_;
};

// The seed rules (seed, seed_framework) act only within epsilon of a surface and never project:
// a particle that moves more than epsilon per step can cross that zone within one step and end
// below the surface before they act (0.23 m into the seed slope at dt = 1/60 s). For each such
// terrain where this can go deeper than the zone itself (fastest arrival speed x dt > 2 epsilon),
// one sentence naming the terrain, the speeds and the coulomb model for large steps. The arrival
// speed is estimated from the state: the fastest approach now, plus the free fall (gravity
// along the normal) of the lowest particle onto the surface, plus the terrain's own largest
// approach speed over [state.t, t_end] (sampled every millisecond).
std::vector<std::string> seed_step_warnings(const Model& model, const State& state,
                                            const Terrains& terrains, Real dt, Real t_end);

}  // namespace jelly
