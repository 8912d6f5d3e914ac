#pragma once
// A contact model between particles and terrains (coulomb, seed, seed_framework): one class per
// model, each in its own file, found through terrain_contact_model() (contact_models.cpp, one
// line per model). The models say where they act:
//  - after each step (resolve_after_step, every integrator), on a range of particles;
//  - inside every force evaluation (acts_in_evaluation / apply_in_evaluation: the explicit
//    integrators only);
//  - as constraints of implicit_euler's solve and of xpbd's and projective dynamics'
//    projections (constrains_solves: those integrators resolve such terrains themselves and the
//    after-step response skips them).
// Contacts a model carries into the next step (the seed rules' contact and friction forces) are
// listed in `carried`, and ContactSolver::add_forces applies them in that step's evaluations.
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

// A particle that touched a terrain at the last after-step response and keeps a contact force
// during the next step: the inward force is cancelled and friction -mu N v_t added.
struct CarriedContact {
  int particle;   // the particle's global index
  Vec3 normal;    // the terrain's outward unit normal there
  Real friction;  // mu of the terrain's contact
};

// What a model's after-step response works on: the step from `before` to `state` (time
// state.t) of size h, against `terrain` with its contact parameters.
struct AfterStepContact {
  const Model& model;           // the model stepped
  const Terrain& terrain;       // the terrain touched
  const ContactParams& params;  // its contact parameters
  const State& before;          // the state at the step's start
  State& state;                 // the state after the step, which the response changes
  Real h;                       // s, the step
};

// A contact model (coulomb, seed, seed_framework): what it does after a step, inside force
// evaluations, or as constraints of a solve. No integrator knows one by name.
class TerrainContactModel {
 public:
  virtual ~TerrainContactModel() = default;
  // The ContactModel value this implements.
  virtual ContactModel kind() const = 0;

  // The response of particles [begin, end) after a step; returns how many touched the terrain.
  // Carried contacts are appended in particle order. Each particle's response is its own (the
  // same bits for any split of the range).
  virtual int resolve_after_step(const AfterStepContact& step, int begin, int end,
                                 std::vector<CarriedContact>& carried) const = 0;

  // True when the model acts inside every force evaluation (apply_in_evaluation).
  virtual bool acts_in_evaluation() const { return false; }
  // Inside a force evaluation at time t on that evaluation's own state (x, v) with its forces f:
  // may change v (a reflection) and add to f.
  virtual void apply_in_evaluation(const Model& /*model*/, const Terrain& /*terrain*/, Real /*t*/,
                                   const VecX& /*x*/, VecX& /*v*/, VecX& /*f*/) const {}

  // True when implicit_euler's solve and the position-based integrators' projections hold this
  // model's contact as constraints (then they resolve it, not the after-step response).
  virtual bool constrains_solves() const { return false; }

 protected:
  TerrainContactModel() = default;
  // For derived models.
  TerrainContactModel(const TerrainContactModel&) = default;
  // For derived models.
  TerrainContactModel& operator=(const TerrainContactModel&) = default;
};

// The model of each ContactModel value.
const TerrainContactModel& terrain_contact_model(ContactModel kind);
// The model of a terrain's contact parameters.
inline const TerrainContactModel& terrain_contact_model(const Terrain& terrain) {
  return terrain_contact_model(terrain.contact().model);
}

}  // namespace jelly
