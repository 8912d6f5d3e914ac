#pragma once
// Parameter identification: the spring and damper coefficients for which a replay of a recorded
// trajectory matches its positions best in the least-squares sense (docs/fitting.md).
#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/body_contact_params.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/terrain/terrain.hpp>

// A recorded trajectory of a jelly (frames of positions, optionally velocities) together with
// everything needed to replay it: the model's structure, the terrains and the integrator and dt.
namespace jelly {

// Builds a fresh set of terrains for one replay (the Simulator owns its terrains). It may be
// called from several threads at once, so it must not share mutable state.
using TerrainFactory = std::function<Terrains()>;

// A recorded motion to fit coefficients to: the model, frame times, positions (and velocities),
// terrains, contact and the integrator it was recorded with.
struct Trajectory {
  // Masses, springs (a, b, rest length, type) and gravity. The coefficients ks and kd are the
  // starting guess of a fit unless FitOptions::initial names other values.
  Model model;
  std::vector<Real> times;       // [T] s, strictly increasing
  std::vector<VecX> positions;   // [T] frames of 3N positions (m)
  std::vector<VecX> velocities;  // empty, or [T] frames of 3N velocities (m/s)
  // Empty, or [T]: the integrator's internal_state() at each frame as the recorded run carried
  // it (implicit_euler's contact pairs between bodies with their friction state, its terrains'
  // contact set; simulate_trajectory keeps them). An implicit_euler window replayed from frame k
  // starts with it; without it (a `jelly run` recording) windows start afresh.
  std::vector<std::vector<Real>> integrator_states;
  TerrainFactory terrains;  // empty = no terrain
  // Contact between bodies (and within one) as the recording ran it; every replay uses it.
  BodyContactParams body_contact;
  std::string integrator = "rk4";        // the integrator the recording was made with
  IntegratorOptions integrator_options;  // the options of that integrator
  Real dt = 0.001;                       // s; every frame interval is a whole number of steps

  // The number of frames.
  int frames() const { return static_cast<int>(times.size()); }
  // True when velocities were recorded.
  bool has_velocities() const { return !velocities.empty(); }
  // Throws InputError naming the first problem: fewer than 3 frames, sizes, times that are not
  // increasing or not a whole number of steps apart, non-finite values, a recording in which
  // nothing moves or no spring ever changes length (nothing to identify).
  void validate() const;
  // Frame k as a state to restart from: recorded velocities when present, else finite
  // differences of the positions (second order: central inside, one-sided at both ends).
  State state(int k) const;
  // The terrains of one replay (none when `terrains` is empty).
  Terrains make_terrains() const;
};

// Simulates `model` from `initial` with the named integrator (also implicit_euler_ceres) and
// records a frame every `frame_interval` (a whole number of steps) until `duration`: a
// synthetic recording with known coefficients, as the tests use.
Trajectory simulate_trajectory(const Model& model, const State& initial, TerrainFactory terrains,
                               const std::string& integrator, Real dt, Real frame_interval,
                               Real duration, bool record_velocities = true,
                               const IntegratorOptions& integrator_options = {},
                               const BodyContactParams& body_contact = {});

}  // namespace jelly

namespace jelly {

// One free coefficient: ks or kd, of one spring type or of all types together, of one body or
// of every body.
struct FitParameter {
  // Which coefficient: stiffness or damping.
  enum class Quantity { kKs, kKd };
  Quantity quantity = Quantity::kKs;  // ks or kd
  std::optional<SpringType> type;     // none = every spring type shares the value
  std::string body;                   // "" = every body shares the value

  // "ks", "kd", "ks.structural", "kd.bending", ..., prefixed "<body>." for one body's:
  // "soft.ks", "stiff.kd.shear".
  std::string name() const;
  // True when it applies to springs of type t.
  bool applies_to(SpringType t) const { return !type || *type == t; }
  // The springs [first, end) of the model it applies to (every spring when `body` is empty);
  // throws InputError (field "free") naming the model's bodies when it has no body `body`.
  std::pair<int, int> spring_range(const Model& model) const;
};

// Parses a comma-separated list such as "ks,kd", "ks.structural,ks.shear,kd" or, per body
// (scene body names), "soft.ks,stiff.ks,kd". Throws InputError (field "free") for an unknown
// name, a duplicate or an overlap ("ks" and "ks.shear", "ks" and "soft.ks"). Whether the bodies
// exist is checked by fit_recording against the trajectory's model.
std::vector<FitParameter> parse_free_parameters(std::string_view list);

// How fit_recording differentiates the residuals (docs/fitting.md, "Exact gradients").
enum class FitGradients {
  kAuto,     // the adjoint when it supports the recording (implicit_euler, ...), else numeric
  kAdjoint,  // the adjoint of implicit_euler; InputError when it does not support the recording
  kNumeric,  // central differences of replays (Levenberg-Marquardt), whatever the integrator
};
// "auto", "adjoint", "numeric"; throws InputError naming `field` for another name.
FitGradients fit_gradients_from_name(std::string_view name, std::string_view field);
std::string_view fit_gradients_name(FitGradients gradients);  // "auto", "adjoint", "numeric"

// How fit_recording fits: the free parameters, their starts, windows, Ceres' tolerances, threads.
struct FitOptions {
  FitGradients gradients = FitGradients::kAuto;  // how the residuals are differentiated
  std::vector<FitParameter> free = parse_free_parameters("ks,kd");  // the coefficients fitted
  // Starting values by parameter name; a parameter not named starts at the mean of its springs'
  // current coefficient in the trajectory's model. Every start must be > 0.
  std::map<std::string, Real> initial;
  // Multiple shooting: windows of this length (s), each replayed from its recorded first frame;
  // 0 = one window over the whole recording.
  Real window = 0.1;
  int max_iterations = 50;           // Ceres' iteration limit
  Real function_tolerance = 1e-10;   // Ceres' relative cost tolerance
  Real gradient_tolerance = 1e-12;   // Ceres' gradient tolerance
  Real parameter_tolerance = 1e-10;  // Ceres' relative step tolerance
  // Full multiple shooting on the velocities: each window's initial velocity becomes 3N extra
  // unknowns, started from the recorded (or finite-difference) velocity. Removes the bias of
  // finite-difference restarts for recordings without velocities, at 2 x 3N more replays of
  // each window per Jacobian (docs/fitting.md). Positions still restart from the recording.
  bool fit_restart_velocities = false;
  // Relative step of the central differences, on the log of the coefficients.
  Real relative_step = 1e-6;
  int num_threads = 1;              // replays run in parallel
  bool compute_covariance = true;   // standard deviations from the covariance
  bool progress_to_stdout = false;  // Ceres' progress lines on stdout

  // Throws InputError naming the first invalid option.
  void validate() const;
};

// One fitted coefficient: its start, value and standard deviations.
struct FittedParameter {
  FitParameter parameter;  // what was fitted
  std::string name;        // its name ("ks", "kd.shear", ...)
  Real initial = 0;        // its starting value
  Real value = 0;          // the fitted value
  // Standard deviation by the delta method, sd(k) = k sd(log k), from the covariance of the
  // log-coefficients; NaN when the covariance could not be computed. `stddev` accounts for the
  // noise of the restart states (docs/fitting.md); `stddev_independent` is the textbook
  // s^2 (J^T J)^-1, which treats every residual as independent and is too small when the
  // recorded positions are noisy.
  Real stddev = 0;
  Real stddev_independent = 0;  // s^2 (J^T J)^-1's, which ignores the restart noise
};

// What fit_recording found: every parameter's estimate, the costs, Ceres' report and the
// covariance.
struct FitResult {
  std::vector<FittedParameter> parameters;  // the estimates, in the order of FitOptions::free
  Real initial_cost = 0;                    // 1/2 sum of squared position residuals (m^2)
  Real final_cost = 0;                      // the same at the end (m^2)
  int iterations = 0;                       // Ceres' iterations
  bool converged = false;                   // Ceres terminated with CONVERGENCE
  std::string termination;                  // Ceres' message
  std::string brief_report;                 // Ceres' brief report
  bool covariance_ok = false;               // true when the standard deviations could be computed
  std::string covariance_message;           // why they could not, or empty
  Real residual_rms = 0;                    // sqrt(2 final_cost / residuals) (m)
  int windows = 0;                          // windows of multiple shooting
  int residuals = 0;                        // position residuals (3 per particle per frame)
  // "adjoint" (exact gradients, Ceres' line search with BFGS) or "numeric" (central differences,
  // Levenberg-Marquardt), and why the numeric path was taken when the adjoint was not.
  std::string gradient_path;
  std::string gradient_reason;  // why the numeric path was taken, or empty
  long adjoint_passes = 0;      // window replays differentiated by the adjoint (forward + backward)
  // The integrator whose adjoint gave the gradients (the recording's), when gradient_path is
  // "adjoint".
  std::string adjoint_integrator;
  // The fitted initial velocity of each window (fit_restart_velocities), else empty.
  std::vector<VecX> restart_velocities;
  long replays = 0;             // window replays (each one simulation of a window)
  Real wall_seconds = 0;        // the whole call
  Real covariance_seconds = 0;  // of which the covariance

  // The estimate named "ks", "kd.shear", ...; throws InputError for a name not fitted.
  const FittedParameter& at(std::string_view name) const;
  // Several lines: estimates with standard deviations, costs, iterations, Ceres' brief report.
  std::string report() const;
};

// Fits the free coefficients of `options` to `trajectory`. Throws InputError for an invalid
// trajectory or options; a fit that does not converge is reported in the result.
FitResult fit_recording(const Trajectory& trajectory, const FitOptions& options = {});

// Writes the fitted values into every spring they apply to.
void apply_fit(Model& model, const FitResult& result);
// A body's material: the fitted values of every body and those of the body named `body`.
void apply_fit(Material& material, const FitResult& result, std::string_view body = "");
void apply_fit(CubeSpec& spec, const FitResult& result);  // the values of every body

// 1/2 sum over the windows of |x_replay - x_recorded|^2 with the model's current coefficients.
Real replay_cost(const Trajectory& trajectory, Real window);

}  // namespace jelly
