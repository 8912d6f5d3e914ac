#pragma once
// Internal to the ARKODE integrators (not part of the public API): RAII owners of SUNDIALS
// objects and the driver that advances y = [x; v] over one contact interval with ERKStep or
// ARKStep, resetting ARKODE only when the state was changed from outside (docs/arkode.md).
#include <memory>
#include <string>
#include <type_traits>

#include <arkode/arkode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly::arkode {

struct ContextDeleter {
  void operator()(SUNContext c) const { SUNContext_Free(&c); }
};
using ContextPtr = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;

struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
using VectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;

struct MatrixDeleter {
  void operator()(SUNMatrix m) const { SUNMatDestroy(m); }
};
using MatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;

struct LinearSolverDeleter {
  void operator()(SUNLinearSolver s) const { SUNLinSolFree(s); }
};
using LinearSolverPtr =
    std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverDeleter>;

// ERKStepFree or ARKStepFree.
struct MemoryDeleter {
  void (*free)(void**) = nullptr;
  void operator()(void* memory) const {
    if (memory != nullptr) free(&memory);
  }
};
using MemoryPtr = std::unique_ptr<void, MemoryDeleter>;

// Throws std::runtime_error if SUNDIALS cannot create a context (out of memory).
ContextPtr make_context();

// What the right-hand side y' = [v; M^-1 f(x, v)] reads: the Dynamics of the current step and
// workspace, so that an evaluation does not allocate.
struct RhsData {
  const Dynamics* dynamics = nullptr;
  VecX x, v, a;
  std::string error;      // the last message of ARKODE's error handler
  void* owner = nullptr;  // the Driver, for callbacks that need more (Jacobian)
};

// ARKRhsFn: ydot = [v; a(x, v)]. Returns 1 (recoverable: ARKODE retries with a smaller step)
// when the accelerations are not finite.
int rhs(realtype t, N_Vector y, N_Vector ydot, void* user_data);

// ARKErrHandlerFn: keeps ARKODE's message (in RhsData::error) instead of printing it.
void keep_error(int error_code, const char* module, const char* function, char* message,
                void* user_data);

// The functions ERKStep and ARKStep share, with identical signatures.
struct StepperApi {
  int (*sstolerances)(void*, realtype, realtype);
  int (*set_user_data)(void*, void*);
  int (*set_err_handler)(void*, ARKErrHandlerFn, void*);
  int (*set_max_num_steps)(void*, long);
  int (*set_max_step)(void*, realtype);
  int (*set_init_step)(void*, realtype);
  int (*set_stop_time)(void*, realtype);
  int (*reset)(void*, realtype, N_Vector);
  int (*evolve)(void*, realtype, N_Vector, realtype*, int);
  int (*get_last_step)(void*, realtype*);
  int (*get_num_steps)(void*, long*);
  int (*get_num_step_attempts)(void*, long*);
  int (*get_num_err_test_fails)(void*, long*);
  char* (*flag_name)(long);
  void (*free)(void**);
};
extern const StepperApi kErkStepApi;
extern const StepperApi kArkStepApi;

// Cumulative counters of one ARKODE memory; accumulated across resets by the Driver.
struct Counters {
  long steps = 0, attempts = 0, error_test_failures = 0, rhs_evaluations = 0;
  long newton_iterations = 0, newton_failures = 0, linear_setups = 0, jacobian_evaluations = 0;
  // Krylov solvers: iterations, convergence failures, right-hand sides of J v difference
  // quotients (not in rhs_evaluations).
  long linear_iterations = 0, linear_failures = 0, linear_rhs_evaluations = 0;
};

// Advances the state over one contact interval [t, t + h] with adaptive internal steps.
class Driver {
 public:
  Driver(std::string name, const StepperApi& api, ArkodeOptions options);
  virtual ~Driver() = default;
  Driver(const Driver&) = delete;
  Driver& operator=(const Driver&) = delete;

  StepResult advance(const Dynamics& dynamics, State& state, Real h);
  // The accumulated ARKODE counters plus the method's own (e.g. factorizations).
  Statistics statistics() const;
  const ArkodeOptions& options() const { return options_; }

 protected:
  // Creates memory_ for y0 at t0 and configures what is specific to the stepper (table,
  // linear solver); returns a SUNDIALS flag (< 0 = failure).
  virtual int create(realtype t0, N_Vector y0) = 0;
  virtual Counters read_counters() const;
  virtual void add_statistics(Statistics& /*stats*/) const {}
  // More about a failure than ARKODE's message (e.g. the linear solver's reason).
  virtual std::string failure_detail() const { return {}; }
  // True: ARKODE steps past the interval end and advance() returns its interpolant there (no
  // stop time; internal steps unlimited unless max_step is set; after a restart the first step
  // is at most the interval). False: every interval ends with an internal step (stop time).
  virtual bool interpolates() const { return false; }
  // A failure message: what failed, SUNDIALS' flag name and its last message.
  std::string failure(const char* call, int flag) const;
  const Counters& total() const { return total_; }

  std::string name_;
  const StepperApi& api_;
  ArkodeOptions options_;
  ContextPtr context_;
  RhsData data_;
  VectorPtr y_;
  // Declared last: freed before the solvers and vectors it uses.
  MemoryPtr memory_;

 private:
  void accumulate();

  VecX last_x_, last_v_;  // the state returned by the last advance()
  Real last_t_ = 0;
  bool contacts_last_ = false;  // the contact solver had contacts at the last advance()
  Real last_h_ = 0;             // ARKODE's last internal step
  Counters total_, seen_;
  long resets_ = 0;
  // Pinned particles: the largest distance of ARKODE's own values from their paths at an
  // interval's end, in units of the error test's weight (rtol |value| + atol), and the restarts
  // that put ARKODE back on the paths when that exceeded 1.
  Real pin_drift_ = 0;
  long pin_resyncs_ = 0;
  bool pin_resync_ = false;
};

}  // namespace jelly::arkode
