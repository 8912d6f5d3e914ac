#pragma once
// The integrator interface: a non-virtual step() that checks its input and keeps counts, over a
// small protected hook each method implements.
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/state.hpp>
#include <jelly/solvers/dynamics.hpp>

namespace jelly {

class BodyContact;    // solvers/contact/detail/body_contact.hpp (internal)
class ContactSolver;  // solvers/contact/detail/contact_solver.hpp (internal)

// Named counters and timings an integrator reports (summary, HDF5 attributes).
using Statistics = std::map<std::string, double>;

// A kind of step that ended without meeting the method's own tolerance (e.g. Newton stopped at
// its iteration limit above its tolerance), counted over the integrator's life: the Simulator
// turns the ones of a run into a warning status (RunStatus::kCompletedWithWarnings).
struct ToleranceMiss {
  std::string what;  // "implicit_euler: Newton did not converge (newton_iterations = 5, ...)"
  long steps = 0;    // steps that missed it
};
// A tolerance as people write it, for ToleranceMiss::what (1e-12, not 9.9999999999999998e-13).
std::string tolerance_text(double value);

// What a step resolved of the contact inside its own solve or iterations, so that finish_step()
// leaves it alone: per step, since it depends on what the step's Dynamics carried.
struct StepContact {
  // The terrains whose model constrains the solves (TerrainContactModel::constrains_solves()):
  // finish_step() then resolves only the others (the seed models) after the step.
  bool terrains = false;
  // The contact between bodies (Dynamics::body_contact()): finish_step() then skips it.
  bool bodies = false;
  // With `terrains`: the particles in terrain contact at the step's end.
  int particles = 0;
};

// A recoverable numerical failure is a returned status, not an exception.
struct StepResult {
  bool ok = true;       // false when the step failed
  std::string message;  // why it failed (empty on success)
  StepContact contact;  // what the step resolved of the contact
  // A step that succeeded.
  static StepResult success() { return {}; }
  // A step that failed, saying why.
  static StepResult failure(std::string why) { return {false, std::move(why), {}}; }
};

// An integration method (explicit Euler, RK4, implicit Euler, ...): a non-virtual step() that
// checks its input and counts, around each method's do_step().
class Integrator {
 public:
  virtual ~Integrator() = default;

  // Advances state (t, x, v) by h under `dynamics`: the integration alone, which may resolve
  // contact inside its solve (StepResult::contact says what it did); finish_step() completes the
  // step (the contact left, then the pins). Throws InputError unless h is finite and > 0 and the
  // state's sizes match the model, or when `dynamics` has seed_framework terrains and the method
  // does not evaluate through Dynamics::stage_acceleration()
  // (integrator_supports_in_evaluation_contact()).
  StepResult step(const Dynamics& dynamics, State& state, Real h);

  // The method's registry name ("rk4", "implicit_euler", ...).
  virtual std::string_view name() const = 0;
  // The order of accuracy of its fixed steps (1 for Euler, 4 for RK4).
  virtual int order() const = 0;
  // True for a method that solves a system per step.
  virtual bool is_implicit() const { return false; }
  // True when the method takes the Jacobians of added forces (Force::add_jacobian) into its
  // solve; an implicit method without them treats added forces explicitly within its step.
  virtual bool uses_force_jacobians() const { return false; }
  // For a method that uses them: what it does with an added force that gives none (the run
  // report's note "force 'name' gives no Jacobian: <this>").
  virtual std::string without_force_jacobian() const;
  // True when the method chooses its own internal steps within each step(h) (error control):
  // the h-convergence of fixed-step methods does not apply to it.
  virtual bool is_adaptive() const { return false; }
  // What the next steps depend on besides the state (warm starts, contact sets), as numbers a
  // checkpoint can store; empty for a method without such state. restore_internal_state() takes
  // back what internal_state() gave (an empty vector: start afresh; a method without state
  // ignores it, e.g. when a run continues with another integrator on purpose) and throws
  // InputError for data it cannot read.
  virtual std::vector<Real> internal_state() const { return {}; }
  // Restores what internal_state() gave.
  virtual void restore_internal_state(const std::vector<Real>& data);
  // Counters of this integrator (steps, and whatever the method adds).
  virtual Statistics statistics() const;
  // The tolerances the method can miss without failing the step, each with the number of steps
  // that missed it so far (empty for methods without an iteration limit below a tolerance).
  virtual std::vector<ToleranceMiss> tolerance_misses() const { return {}; }

  // Steps taken so far.
  long steps() const { return steps_; }

 protected:
  // The method's step, called by step() after its checks.
  virtual StepResult do_step(const Dynamics& dynamics, State& state, Real h) = 0;

 private:
  long steps_ = 0;
};

// Completes a step that Integrator::step() took from `before` to `state` with `result` (ok):
// the contact between bodies unless the step resolved it (`bodies` may be null: none), then
// every terrain's contact, or only the after-step models' when the step resolved the others
// (the step's contacts added to the count), then the pins: pinned particles end the step
// exactly on their paths, whatever the method and the contact did with them. The one place
// pins are enforced; the Simulator and anything stepping an integrator itself call it.
void finish_step(const StepResult& result, ContactSolver& contacts, BodyContact* bodies,
                 const Model& model, const Terrains& terrains, const State& before, State& state,
                 Real h, int threads = 1);

// What InputError says is allowed when `integrator` meets a seed_framework terrain.
std::string in_evaluation_contact_requirement(std::string_view integrator);

// Resizes v to n entries only when its size differs (no allocation in steady state).
void ensure_size(VecX& v, Eigen::Index n);

}  // namespace jelly
