#pragma once
// Steps a model among terrains with an integrator: contact after every step (or inside it, for
// an integrator that resolves contact itself), observers at a chosen output interval, and a
// divergence guard that stops the run with a report.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <jelly/core/force.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/body_contact_params.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>
#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/run_report.hpp>

namespace jelly {

class BodyContact;    // solvers/contact/detail/body_contact.hpp (internal)
class ContactSolver;  // solvers/contact/detail/contact_solver.hpp (internal)
class Simulator;
class SpringBands;
namespace parallel {
class TeamChooser;
}
class ObserverList;

// Called with the simulator at the first output time and then every output interval.
// An observer knows the simulators it was added to and leaves them when it is destroyed, so a
// simulator never calls a destroyed observer (and a destroyed simulator is forgotten by its
// observers). Observers and their simulators are used from one thread.
class Observer {
 public:
  Observer() = default;
  // A copy is a new observer: it observes nothing until it is added itself.
  Observer(const Observer& /*other*/) noexcept {}
  // A copy is a new observer (see the copy constructor).
  Observer& operator=(const Observer& /*other*/) noexcept { return *this; }
  // Removes this observer from every simulator it was added to.
  virtual ~Observer();

  // Called at the first output time and then every output interval.
  virtual void on_frame(const Simulator& simulator) = 0;
  // Called when run_until() ends, with its report.
  virtual void on_finish(const Simulator& /*simulator*/, const RunReport& /*report*/) {}
  // Called by Simulator::add_observer before adding it: an observer made for one simulator's
  // model (a recorder) throws InputError for a simulator it does not fit.
  virtual void check_simulator(const Simulator& /*simulator*/) const {}
  // Removes this observer from every simulator it was added to (as its destruction does; a
  // simulator that shared its ownership releases its share, which may destroy it).
  void leave_simulators();

 private:
  friend class ObserverList;
  std::vector<ObserverList*> lists_;  // the simulators' lists that hold this observer
};

// The observers of a simulator (used by Simulator; not for direct use): links that both sides
// undo on destruction. Observers removed or destroyed during a callback are skipped, never
// called after their removal.
class ObserverList {
 public:
  ObserverList() = default;
  // Takes the links of `other`.
  ObserverList(ObserverList&& other) noexcept;
  // Takes the links of `other`.
  ObserverList& operator=(ObserverList&& other) noexcept;
  ObserverList(const ObserverList&) = delete;
  ObserverList& operator=(const ObserverList&) = delete;
  ~ObserverList();

  // Adding an observer that is already in the list does nothing.
  void add(Observer& observer);
  void add(std::shared_ptr<Observer> observer);  // shared ownership: kept alive while added
  // False when the observer was not in the list.
  bool remove(const Observer& observer);
  std::size_t size() const;  // the number of observers
  // Calls f(observer) for each observer, in the order they were added.
  template <typename F>
  void for_each(F f);

 private:
  friend class Observer;
  void forget(const Observer* observer);  // the observer is being destroyed
  void relink(ObserverList* from);        // after a move: the observers now point here
  void clear();
  std::vector<Observer*> observers_;  // null: removed while iterating
  std::vector<std::shared_ptr<Observer>> owned_;
  int iterating_ = 0;
};

template <typename F>
void ObserverList::for_each(F f) {
  ++iterating_;
  try {
    // Index-based: observers added during a callback are called in the same pass.
    for (std::size_t i = 0; i < observers_.size(); ++i)
      if (observers_[i] != nullptr) f(*observers_[i]);
  } catch (...) {
    --iterating_;
    throw;
  }
  if (--iterating_ == 0) {
    observers_.erase(std::remove(observers_.begin(), observers_.end(), nullptr), observers_.end());
  }
}

// How a Simulator steps: dt, output interval, divergence guard, threads, crush limits.
struct SimulatorOptions {
  Real dt = 0.001;             // s, > 0
  Real output_interval = 0;    // s between observer frames; 0 = every step
  DivergenceGuard divergence;  // when the run stops as diverged
  // Threads for the force loop, the integrators' solves and the contact after a step; 0 = all
  // cores this process may run on or one thread, chosen step by step from which ran faster (a
  // busy neighbour can make a team slower than one thread; docs/threads.md). Results are the
  // same bit for bit for any value.
  int threads = 0;
  // When the end of a run reports a body crushed (run_report.hpp).
  CrushLimits crush{};
  // Throws InputError naming the first value out of range.
  void validate() const;
};

// The values of a model that live edits change (Simulator::set_spring_coefficients, set_gravity,
// set_particle_mass, pins): a snapshot of an edited model carries them.
struct ModelValues {
  std::vector<Real> ks;   // [M] per spring (N/m)
  std::vector<Real> kd;   // [M] per spring (N s/m)
  VecX mass;              // [N]
  Vec3 gravity{0, 0, 0};  // m/s^2
  Pins pins;              // the pins with their paths
};

// What the future of a run depends on besides the model, terrains, integrator and options: a
// simulator restored from it continues bit for bit (for integrators that keep no state between
// steps, which all explicit ones do).
struct SimulatorSnapshot {
  // The largest step count a snapshot may carry: 2^53 (exact as a double; no run takes that many
  // steps, and counting on from it cannot overflow).
  static constexpr long kMaxTotalSteps = 1L << 53;
  State state;                                // time, positions, velocities
  std::vector<CarriedContact> seed_contacts;  // active during the next step
  int contact_count = 0;                      // contacts resolved so far
  long total_steps = 0;  // at most kMaxTotalSteps (the count goes on from there)
  // Time of the next observer frame (taken inside on_frame: that frame's own time, which the
  // frame restore() emits first moves on as the original run did).
  Real next_output = 0;
  // The integrator's internal_state() (warm starts, contact sets; empty for most methods).
  std::vector<Real> integrator_state;
  // After a live edit of the model: its edited values, which restore() puts back (so that a
  // restart after an edit continues exactly); empty for a model as it was built.
  std::optional<ModelValues> model_values;
};

// Names a force added to a simulator (Simulator::add_force), for removing it.
using ForceHandle = long;

// Steps a model among terrains with an integrator: contact, pins, forces, observers at the output
// interval and a divergence guard (docs/scenes.md, README's "Library API").
class Simulator {
 public:
  // Throws InputError for an invalid model, state size or option.
  Simulator(Model model, State state, std::unique_ptr<Integrator> integrator,
            SimulatorOptions options = {});
  ~Simulator();
  // Moves the simulator (observers follow it).
  Simulator(Simulator&&) noexcept;
  // Moves the simulator (observers follow it).
  Simulator& operator=(Simulator&&) noexcept;

  // Throws InputError for a seed_framework terrain when the integrator does not support it.
  void add_terrain(std::unique_ptr<Terrain> terrain);
  // Removes terrains()[index] (the active contacts are kept for the others). Throws InputError
  // for an index out of range.
  void remove_terrain(int index);
  // Puts `terrain` in place of terrains()[index] (a terrain moved, reshaped or given another
  // contact between steps; the others keep their indices). Contacts carried from the last step
  // (implicit_euler's friction state) stay with the terrain at that index and are checked
  // against the new one. Throws InputError as add_terrain and remove_terrain do; nothing
  // changes then.
  void replace_terrain(int index, std::unique_ptr<Terrain> terrain);

  // Forces of your own (core/force.hpp): evaluated at every force evaluation of every
  // integrator, after the model's own, until removed. Returns the handle remove_force() takes.
  // Throws InputError for null or a force whose validate() refuses this model.
  ForceHandle add_force(std::shared_ptr<Force> force);
  // False when no force has this handle.
  bool remove_force(ForceHandle handle);
  // The added forces, in order.
  const ForceList& forces() const { return forces_; }

  // Live edits of the model between steps, validated like a scene (an invalid value throws
  // InputError naming the scene's field and changes nothing). The next step uses them; a
  // checkpoint taken after them holds the edited model (model()).
  // ks and kd of every spring of `type` in body `body` (N/m, N s/m; finite, >= 0).
  void set_spring_coefficients(int body, SpringType type, SpringCoefficients coefficients);
  // Sets gravity (m/s^2) for the next steps.
  void set_gravity(const Vec3& gravity);
  // Every particle of body `body` gets `particle_mass` (kg, finite, > 0).
  void set_particle_mass(int body, Real particle_mass);
  // Replaces the integrator, keeping the model, terrains, forces, pins, observers, options and
  // state; its internal state starts afresh. Throws InputError for null or for an integrator
  // that cannot handle a terrain of this simulator (seed_framework).
  void set_integrator(std::unique_ptr<Integrator> integrator);
  // Sets options().dt, options().output_interval (validated like SimulatorOptions).
  void set_dt(Real dt);
  // Sets the time between observer frames (s; 0 = every step).
  void set_output_interval(Real interval);
  // Pins particle `particle` (global index) to move along `path` from `anchor` (its position
  // at t = 0 of the path), or re-pins it when it is pinned already. Throws InputError for an
  // index out of range or a non-finite anchor.
  void set_pin(int particle, const Vec3& anchor, Path path);
  // Drives pinned particle `particle` from now on: at time t >= now it is at
  // position + velocity (t - now) (the controller's target for the next steps). Throws
  // InputError when the particle is not pinned or a value is not finite.
  void set_pin_target(int particle, const Vec3& position, const Vec3& velocity = Vec3(0, 0, 0));
  // Frees a pinned particle; false when it was not pinned.
  bool remove_pin(int particle);
  // Contact between bodies and within a body (default: between bodies, when there are two or
  // more). Throws InputError for invalid parameters.
  void set_body_contact(const BodyContactParams& params);
  // Throws InputError naming both bodies when two bodies (or, with self-contact, two parts of
  // one body) overlap in the current state.
  void check_no_overlap();
  // Calls `observer` at every frame of the following runs until it is removed or destroyed (it
  // then leaves the simulator by itself). Adding it twice adds it once.
  void add_observer(Observer& observer);
  // The same, and the simulator shares the observer's ownership: it stays alive while added
  // (for observers nobody else keeps, e.g. a progress bar). Throws InputError for null.
  void add_observer(std::shared_ptr<Observer> observer);
  // Stops calling `observer` (and releases the simulator's share of it); false when it was not
  // added. Allowed inside a callback: the observer is not called again.
  bool remove_observer(const Observer& observer);
  // The observers added.
  std::size_t num_observers() const { return observers_.size(); }

  // One step of options().dt, then contact. Returns the integrator's failure, if any; does not
  // check divergence (run_until does).
  StepResult step();
  // Steps until t_end (the last step lands within dt / 2 of it), calling observers, and stops
  // early on divergence or integrator failure. An exception from a force of the user's leaves
  // the simulator at the last completed step and propagates.
  RunReport run_until(Real t_end);

  // The model, with its live edits.
  const Model& model() const { return model_; }
  // The state: time, positions, velocities.
  const State& state() const { return state_; }
  // Springs pulling particles to points (the viewer's mouse drag): part of the forces of every
  // step until replaced; implicit integrators take their Jacobian into the solve. Throws
  // InputError for an invalid anchor (validate_anchors). Not part of snapshots.
  void set_anchors(AnchorSprings anchors);
  // The anchor springs.
  const AnchorSprings& anchors() const { return anchors_; }
  // For changing positions or velocities between steps in place (an external force, a drag),
  // keeping the active contacts, the step count and the output clock; sizes must not change.
  // The buffers of state().x and state().v keep their address for the simulator's life (also
  // across set_state and restore), so views of them (Python, the viewer) stay valid.
  State& mutable_state() { return state_; }
  // Replaces the state (a restart); forgets the active contacts.
  void set_state(State state);
  // What restore() needs to continue this run bit for bit.
  SimulatorSnapshot snapshot() const;
  // Continues from a snapshot (taken from a simulator with the same model, terrains, integrator
  // and options; a snapshot of an edited model puts its edited values back); the next
  // run_until() first emits a frame of the restored state. Throws InputError for a snapshot
  // that does not fit the model.
  void restore(SimulatorSnapshot snapshot);
  // The terrains, in order.
  const Terrains& terrains() const { return terrains_; }
  // The integrator.
  const Integrator& integrator() const { return *integrator_; }
  // The integrator.
  Integrator& integrator() { return *integrator_; }
  // The options.
  const SimulatorOptions& options() const { return options_; }
  // Sets options().threads (0 = all cores). Throws InputError for a negative count.
  void set_threads(int threads);
  // The contact machinery (internal types: for jelly's own programs and tests).
  const ContactSolver& contacts() const;
  // The contact between bodies and within one.
  const BodyContact& body_contact() const;
  // Steps taken since the run began.
  long total_steps() const { return total_steps_; }
  // Live edits of the model so far (0: the model as it was built).
  long model_revision() const { return model_revision_; }
  // Force evaluations since the run began.
  long force_evaluations() const { return force_evaluations_; }

 private:
  // add_terrain's and remove_terrain's checks (InputError naming terrains[index]).
  void check_terrain(const Terrain* terrain, size_t index) const;
  void check_terrain_index(int index) const;
  void emit_frame();
  // After an edit of model_: the force loop's bands again, and the model validated.
  void model_changed();
  // The notes of this run (forces an implicit integrator takes explicitly), once per force and
  // integrator.
  void note_forces(RunReport& report);
  // The team size of the next step: options_.threads, or team_'s choice for 0.
  int step_threads();

  Model model_;
  std::unique_ptr<const SpringBands> bands_;  // the vectorised force loop over model_'s springs
  State state_;
  std::unique_ptr<Integrator> integrator_;
  // The team size of each step when options_.threads is 0 (created at the first such step).
  std::unique_ptr<parallel::TeamChooser> team_;
  SimulatorOptions options_;
  Terrains terrains_;
  // Behind pointers so that this header needs no contact internals; never null (but in a
  // moved-from simulator).
  std::unique_ptr<ContactSolver> contacts_;
  std::unique_ptr<BodyContact> body_contact_;
  State before_;  // the state at the start of the current step
  ObserverList observers_;
  AnchorSprings anchors_;
  ForceList forces_;
  std::vector<ForceHandle> force_handles_;  // parallel to forces_
  ForceHandle next_force_handle_ = 1;
  std::vector<std::string> noted_;  // the notes given so far
  long total_steps_ = 0;
  long model_revision_ = 0;
  long force_evaluations_ = 0;
  long frames_ = 0;
  Real next_output_ = 0;
};

}  // namespace jelly
