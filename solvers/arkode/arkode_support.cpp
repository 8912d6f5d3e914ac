#include <jelly/solvers/arkode/detail/arkode_support.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>

namespace jelly::arkode {

namespace {
// ARKODE's pinned values may leave their paths by this many error weights (rtol |value| + atol)
// before the next interval restarts from the paths. Its error test bounds the weighted RMS of a
// step's local error by 1; a single component of an interval's several steps may exceed that.
// Measured on a mass shaken by a driven pin (test Arkode.DrivenPinsStayOnTheirPathsInsideArkode):
// with 1, the inexact-Newton CG restarted every second interval and ended 50 times less
// accurate than with 100.
constexpr Real kPinDriftLimit = 100;
}  // namespace

ContextPtr make_context() {
  SUNContext context = nullptr;
  if (SUNContext_Create(nullptr, &context) != 0 || context == nullptr)
    throw std::runtime_error("SUNDIALS: SUNContext_Create failed");
  return ContextPtr(context);
}

int rhs(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto& d = *static_cast<RhsData*>(user_data);
  const Eigen::Index n = d.x.size();
  const Eigen::Map<const VecX> yy(N_VGetArrayPointer(y), 2 * n);
  Eigen::Map<VecX> yd(N_VGetArrayPointer(ydot), 2 * n);
  d.x = yy.head(n);
  d.v = yy.tail(n);
  d.dynamics->acceleration(t, d.x, d.v, d.a);
  yd.head(n) = d.v;
  yd.tail(n) = d.a;
  return d.a.allFinite() ? 0 : 1;
}

void keep_error(int /*error_code*/, const char* module, const char* function, char* message,
                void* user_data) {
  auto& d = *static_cast<RhsData*>(user_data);
  d.error = std::string(module) + "::" + function + ": " + message;
}

const StepperApi kErkStepApi{ERKStepSStolerances,
                             ERKStepSetUserData,
                             ERKStepSetErrHandlerFn,
                             ERKStepSetMaxNumSteps,
                             ERKStepSetMaxStep,
                             ERKStepSetInitStep,
                             ERKStepSetStopTime,
                             ERKStepReset,
                             ERKStepEvolve,
                             ERKStepGetLastStep,
                             ERKStepGetNumSteps,
                             ERKStepGetNumStepAttempts,
                             ERKStepGetNumErrTestFails,
                             ERKStepGetReturnFlagName,
                             ERKStepFree};

const StepperApi kArkStepApi{ARKStepSStolerances,
                             ARKStepSetUserData,
                             ARKStepSetErrHandlerFn,
                             ARKStepSetMaxNumSteps,
                             ARKStepSetMaxStep,
                             ARKStepSetInitStep,
                             ARKStepSetStopTime,
                             ARKStepReset,
                             ARKStepEvolve,
                             ARKStepGetLastStep,
                             ARKStepGetNumSteps,
                             ARKStepGetNumStepAttempts,
                             ARKStepGetNumErrTestFails,
                             ARKStepGetReturnFlagName,
                             ARKStepFree};

Driver::Driver(std::string name, const StepperApi& api, ArkodeOptions options)
    : name_(std::move(name)),
      api_(api),
      options_(std::move(options)),
      context_(make_context()),
      memory_(nullptr, MemoryDeleter{api.free}) {}

std::string Driver::failure(const char* call, int flag) const {
  // The flag name is allocated with malloc by SUNDIALS.
  char* flag_name = api_.flag_name(flag);
  std::string why = name_ + ": " + call + " returned " + (flag_name ? flag_name : "?");
  std::free(flag_name);
  if (!data_.error.empty()) why += " (" + data_.error + ")";
  const std::string detail = failure_detail();
  if (!detail.empty()) why += "; " + detail;
  return why;
}

Counters Driver::read_counters() const {
  Counters c;
  void* m = memory_.get();
  api_.get_num_steps(m, &c.steps);
  api_.get_num_step_attempts(m, &c.attempts);
  api_.get_num_err_test_fails(m, &c.error_test_failures);
  return c;
}

void Driver::accumulate() {
  const Counters now = read_counters();
  total_.steps += now.steps - seen_.steps;
  total_.attempts += now.attempts - seen_.attempts;
  total_.error_test_failures += now.error_test_failures - seen_.error_test_failures;
  total_.rhs_evaluations += now.rhs_evaluations - seen_.rhs_evaluations;
  total_.newton_iterations += now.newton_iterations - seen_.newton_iterations;
  total_.newton_failures += now.newton_failures - seen_.newton_failures;
  total_.linear_setups += now.linear_setups - seen_.linear_setups;
  total_.jacobian_evaluations += now.jacobian_evaluations - seen_.jacobian_evaluations;
  total_.linear_iterations += now.linear_iterations - seen_.linear_iterations;
  total_.linear_failures += now.linear_failures - seen_.linear_failures;
  total_.linear_rhs_evaluations += now.linear_rhs_evaluations - seen_.linear_rhs_evaluations;
  seen_ = now;
}

StepResult Driver::advance(const Dynamics& dynamics, State& state, Real h) {
  const Eigen::Index n = state.x.size();
  data_.dynamics = &dynamics;
  ensure_size(data_.x, n);
  ensure_size(data_.v, n);
  ensure_size(data_.a, n);
  data_.error.clear();

  // Contacts change the state (projection, impulses) and, for the seed model, the forces of the
  // next interval: ARKODE's history (step size, FSAL stage) is then invalid and it restarts.
  const bool contacts = dynamics.contacts().contact_count() > 0;
  const bool fresh = memory_ == nullptr || last_x_.size() != n;
  const bool restart = fresh || contacts || contacts_last_ || pin_resync_ || state.t != last_t_ ||
                       state.x != last_x_ || state.v != last_v_;
  if (pin_resync_ && !fresh) ++pin_resyncs_;
  pin_resync_ = false;
  contacts_last_ = contacts;
  // Interpolating drivers step past the interval end (no limit by default); the others stop
  // there.
  const Real max_step = options_.max_step > 0 ? options_.max_step : (interpolates() ? 0.0 : h);
  const Real first_step = max_step > 0 ? std::min(max_step, interpolates() ? h : max_step) : h;
  if (restart) {
    if (fresh) {
      memory_.reset();
      y_.reset(N_VNew_Serial(2 * n, context_.get()));
      if (!y_) return StepResult::failure(name_ + ": N_VNew_Serial failed (out of memory)");
    }
    // Pinned particles start on their paths (a state made before the run, e.g. at rest, may
    // hold another velocity than a driven pin's): ARKODE integrates them from there.
    const Pins& pins = dynamics.model().pins;
    if (!pins.empty()) pins.apply(state.t, state.x, state.v);
    Eigen::Map<VecX> y(N_VGetArrayPointer(y_.get()), 2 * n);
    y.head(n) = state.x;
    y.tail(n) = state.v;
    if (fresh) {
      const int flag = create(state.t, y_.get());
      if (flag < 0 || !memory_) {
        memory_.reset();
        return StepResult::failure(failure("create", flag));
      }
      void* m = memory_.get();
      int f = api_.set_user_data(m, &data_);
      if (f >= 0) f = api_.sstolerances(m, options_.rtol, options_.atol);
      if (f >= 0) f = api_.set_max_num_steps(m, options_.max_steps);
      if (f < 0) {
        memory_.reset();
        return StepResult::failure(failure("setting the options", f));
      }
      seen_ = read_counters();
    } else {
      accumulate();
      const int f = api_.reset(memory_.get(), state.t, y_.get());
      if (f < 0) return StepResult::failure(failure("Reset", f));
      seen_ = read_counters();
      ++resets_;
    }
    // Start from the last internal step taken before the restart (0 = ARKODE's estimate, on
    // the first call). Measured on a jelly resting on the floor (docs/arkode.md), this costs
    // fewer evaluations than ARKODE's estimate or its controller's proposal, which a contact
    // often rejects.
    const int f = api_.set_init_step(memory_.get(), std::min(last_h_, first_step));
    if (f < 0) return StepResult::failure(failure("SetInitStep", f));
  }

  void* m = memory_.get();
  const Real t_end = state.t + h;
  int flag = interpolates() ? 0 : api_.set_stop_time(m, t_end);
  if (flag >= 0) flag = api_.set_max_step(m, max_step);
  if (flag < 0) return StepResult::failure(failure("setting the stop time", flag));
  realtype t_reached = state.t;
  flag = api_.evolve(m, t_end, y_.get(), &t_reached, ARK_NORMAL);
  accumulate();
  if (flag < 0) {
    // The next call must start from the state it is given.
    last_x_.resize(0);
    memory_.reset();
    return StepResult::failure(failure("Evolve", flag) + " at t = " + to_text(t_reached));
  }
  const Eigen::Map<const VecX> y(N_VGetArrayPointer(y_.get()), 2 * n);
  state.x = y.head(n);
  state.v = y.tail(n);
  state.t = t_end;
  // Pinned particles end on their paths (as Integrator::step leaves them): the next interval
  // then starts from the state kept here, without a restart. ARKODE's own values for them
  // follow the paths within its error test (their accelerations are the paths', and the
  // iterative Newton solves prescribe their velocity changes); where they have drifted further
  // (measured here, in units of the error weight), the next interval restarts from the paths.
  const Pins& pins = dynamics.model().pins;
  if (!pins.empty()) {
    Real drift = 0;
    for (int k = 0; k < pins.size(); ++k) {
      const int i = pins.particles[k];
      const PathSample p = pins.sample(k, state.t);
      const Vec3 x = pins.anchors[k] + p.offset;
      for (int a = 0; a < 3; ++a) {
        const Real wx = options_.rtol * std::abs(x[a]) + options_.atol;
        const Real wv = options_.rtol * std::abs(p.velocity[a]) + options_.atol;
        drift = std::max({drift, std::abs(state.x[3 * i + a] - x[a]) / wx,
                          std::abs(state.v[3 * i + a] - p.velocity[a]) / wv});
      }
    }
    pin_drift_ = std::max(pin_drift_, drift);
    pin_resync_ = drift > kPinDriftLimit;
    pins.apply(state.t, state.x, state.v);
  }
  last_x_ = state.x;
  last_v_ = state.v;
  last_t_ = state.t;
  realtype h_last = 0;
  if (api_.get_last_step(m, &h_last) >= 0 && h_last > 0) last_h_ = h_last;
  return StepResult::success();
}

Statistics Driver::statistics() const {
  Statistics s;
  s["arkode_steps"] = static_cast<double>(total_.steps);
  s["arkode_step_attempts"] = static_cast<double>(total_.attempts);
  s["arkode_error_test_failures"] = static_cast<double>(total_.error_test_failures);
  s["rhs_evaluations"] = static_cast<double>(total_.rhs_evaluations);
  s["arkode_resets"] = static_cast<double>(resets_);
  if (pin_drift_ > 0 || pin_resyncs_ > 0) {
    s["arkode_pin_drift"] = pin_drift_;
    s["arkode_pin_resyncs"] = static_cast<double>(pin_resyncs_);
  }
  add_statistics(s);
  return s;
}

}  // namespace jelly::arkode
