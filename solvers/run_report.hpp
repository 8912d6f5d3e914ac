#pragma once
// What a run returns: how it ended, where, and what it cost.
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/integrators/integrator.hpp>

// The one definition of "diverged" shared by the Simulator and jelly-bench: a non-finite
// position or velocity, a particle faster than max_speed, one farther than max_distance from
// the origin, or (when max_energy is finite) a total energy above max_energy.
namespace jelly {

// When a run counts as diverged: speed, distance from the origin, total energy, NaN or Inf.
struct DivergenceGuard {
  Real max_speed = 500;     // m/s
  Real max_distance = 1e4;  // m
  // Cap on the total energy (kinetic + elastic + gravitational, J); infinite = not checked.
  // jelly-bench sets it to the initial energy plus the work terrains can do plus a tolerance
  // (docs/benchmarking.md); checking it costs one pass over the springs per step.
  Real max_energy = std::numeric_limits<Real>::infinity();

  // Throws InputError for a limit that is not > 0.
  void validate() const;
  // The reason the state counts as diverged, or nothing. Without the model the energy is not
  // checked. The particles are scanned on up to `threads` threads (the same answer for any
  // count: the first offending particle is named).
  std::optional<std::string> check(const State& state, int threads = 1) const;
  // The same, with the model's energy checked against max_energy.
  std::optional<std::string> check(const Model& model, const State& state, int threads = 1) const;
};

}  // namespace jelly

namespace jelly {

// How a run ended.
enum class RunStatus {
  kCompleted,              // reached the requested time
  kCompletedWithWarnings,  // reached it, but some steps missed the solver's own tolerance, or
                           // a body ended crushed (CrushLimits)
  kDiverged,               // NaN, Inf or runaway speed: the divergence guard stopped the run
  kSolverFailed,  // the integrator returned a failure (e.g. a matrix not positive definite)
};
// "completed", "completed_with_warnings", "diverged", "solver_failed".
std::string_view run_status_name(RunStatus status);

// What a run did: how it ended, the time reached, steps, wall time, the integrator's counters and
// notes.
struct RunReport {
  RunStatus status = RunStatus::kCompleted;  // how the run ended
  Real t = 0;                                // simulated time reached
  long steps = 0;                            // steps taken in this run
  // Why the run stopped early, or for kCompletedWithWarnings which tolerances how many steps
  // missed ("implicit_euler: Newton did not converge (...) on 111 of 180 steps"); empty when
  // completed.
  std::string reason;
  double wall_seconds = 0;     // s of wall time the run took
  long force_evaluations = 0;  // force evaluations of the run
  Statistics statistics;       // the integrator's counters
  // What the caller should know that is not a warning: an added force without Jacobians that
  // an implicit integrator treats explicitly within its step, said once per simulator.
  std::vector<std::string> notes;

  // Reached the requested time (with or without warnings).
  bool ok() const {
    return status == RunStatus::kCompleted || status == RunStatus::kCompletedWithWarnings;
  }
  // Reached the requested time, with warnings.
  bool has_warnings() const { return status == RunStatus::kCompletedWithWarnings; }
  // One line: status, time, steps, wall time (and the reason when it stopped early).
  std::string brief() const;
};

}  // namespace jelly

namespace jelly {

// When a run that reached its end says a body is crushed (scene key "crush"): its volume
// (core/measures.hpp, body_volume) below min_volume_ratio times its rest volume, or more than
// max_inverted_fraction of its cells (tetrahedra) inverted.
struct CrushLimits {
  Real min_volume_ratio = 0.5;        // in [0, 1]; 0: never by volume
  Real max_inverted_fraction = 0.05;  // in [0, 1]; 1: never by inverted cells

  // Throws InputError naming "crush."field.
  void validate() const;
};

// Adds each body's volume ratio and inverted cells (lattice bodies) or tetrahedra (tet meshes)
// at x to report.statistics ("volume_ratio.<body>", "inverted_cells.<body>" or
// "inverted_tets.<body>"); a note for each body without volume (a cloth: not checked); and for
// a body beyond `limits`, when the run reached its end, the status kCompletedWithWarnings with
// the body and figure in the reason. O(cells), no allocation beyond the report's own strings.
void report_crushed_bodies(const Model& model, const VecX& x, const CrushLimits& limits,
                           RunReport& report);

}  // namespace jelly
