#pragma once
// Contact between particles and terrains, the same for every integrator (docs/contact.md):
//  1. after each integrator step, resolve() applies each terrain's contact model to the new
//     state: velocity impulses (restitution, friction) and, for coulomb, projection out of the
//     surface and the tangential displacement that friction removed during the step (an
//     implicit integrator may resolve the coulomb terrains inside its solve instead);
//  2. during the next step, every force evaluation calls add_forces(), which applies the seed
//     model's contact and friction forces to the particles that collided in step 1.
#include <memory>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

using Terrains = std::vector<std::unique_ptr<Terrain>>;

class ContactSolver {
 public:
  // A particle the seed model flagged at the last resolve(): it gets the contact and friction
  // forces during the next step.
  struct SeedContact {
    int particle;
    Vec3 normal;
    Real friction;
  };

  // Which terrains resolve() answers: all, or only those with the seed model (when the
  // integrator resolved the coulomb ones inside its step).
  enum class Scope { kAll, kSeedOnly };

  // Applies every terrain's contact response to `state` (time state.t) after a step of size h
  // from the state `before`, on up to `threads` threads (each particle's response is its own;
  // the seed contacts are listed in particle order for any thread count).
  void resolve(const Model& model, const Terrains& terrains, const State& before, State& state,
               Real h, Scope scope = Scope::kAll, int threads = 1);
  // Adds contacts resolved elsewhere (inside an implicit step) to contact_count().
  void add_resolved(int count) { contact_count_ += count; }
  // Seed model: for each particle that collided at the last resolve() and whose force f pushes
  // into the surface, cancels the inward normal force N and adds the friction -mu N v_t.
  void add_forces(const VecX& v, VecX& f) const;

  // Particle-terrain contacts found by the last resolve().
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

}  // namespace jelly
