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

// A recoverable numerical failure is a returned status, not an exception.
struct StepResult {
  bool ok = true;
  std::string message;
  static StepResult success() { return {}; }
  static StepResult failure(std::string why) { return {false, std::move(why)}; }
};

class Integrator {
 public:
  virtual ~Integrator() = default;

  // Advances state (t, x, v) by h under `dynamics`. Throws InputError unless h is finite and
  // > 0 and the state's sizes match the model, or when `dynamics` has seed_framework terrains
  // and the method does not support them.
  StepResult step(const Dynamics& dynamics, State& state, Real h);

  virtual std::string_view name() const = 0;
  virtual int order() const = 0;
  virtual bool is_implicit() const { return false; }
  // True when the method takes the Jacobians of added forces (Force::add_jacobian) into its
  // solve; an implicit method without them treats added forces explicitly within its step.
  virtual bool uses_force_jacobians() const { return false; }
  // True when the method chooses its own internal steps within each step(h) (error control):
  // the h-convergence of fixed-step methods does not apply to it.
  virtual bool is_adaptive() const { return false; }
  // True when every force evaluation of do_step() goes through Dynamics::stage_acceleration(),
  // so that seed_framework terrains act inside it (the explicit methods). The others reject
  // such terrains: a velocity reflection inside an implicit solve's or ARKODE's right-hand side
  // is not a function of the state they iterate on (docs/contact.md).
  virtual bool supports_in_evaluation_contact() const { return false; }
  // True when do_step() already applied the contact of the coulomb terrains (inside its solve);
  // the Simulator then applies only the seed model's contact after the step.
  virtual bool resolves_contact() const { return false; }
  // True when do_step() resolved the contact between bodies (Dynamics::body_contact()) inside
  // its solve; the Simulator then does not resolve it after the step.
  virtual bool resolves_body_contact() const { return false; }
  // When resolves_contact(): the particles in coulomb contact at the end of the last step.
  virtual int contacts_resolved() const { return 0; }
  // What the next steps depend on besides the state (warm starts, contact sets), as numbers a
  // checkpoint can store; empty for a method without such state. restore_internal_state() takes
  // back what internal_state() gave (an empty vector: start afresh; a method without state
  // ignores it, e.g. when a run continues with another integrator on purpose) and throws
  // InputError for data it cannot read.
  virtual std::vector<Real> internal_state() const { return {}; }
  virtual void restore_internal_state(const std::vector<Real>& data);
  // Counters of this integrator (steps, and whatever the method adds).
  virtual Statistics statistics() const;
  // The tolerances the method can miss without failing the step, each with the number of steps
  // that missed it so far (empty for methods without an iteration limit below a tolerance).
  virtual std::vector<ToleranceMiss> tolerance_misses() const { return {}; }

  long steps() const { return steps_; }

 protected:
  virtual StepResult do_step(const Dynamics& dynamics, State& state, Real h) = 0;

 private:
  long steps_ = 0;
};

// The contact after a step of `integrator` from `before` to `state` (as the Simulator does it):
// every terrain's, or, when the integrator resolved the coulomb terrains inside its step, only
// the seed model's, with the integrator's contacts added to the count.
void resolve_contact_after_step(const Integrator& integrator, ContactSolver& contacts,
                                const Model& model, const Terrains& terrains, const State& before,
                                State& state, Real h, int threads = 1);

// What InputError says is allowed when `integrator` meets a seed_framework terrain.
std::string in_evaluation_contact_requirement(std::string_view integrator);

// Resizes v to n entries only when its size differs (no allocation in steady state).
inline void ensure_size(VecX& v, Eigen::Index n) {
  if (v.size() != n) v.setZero(n);
}

}  // namespace jelly
