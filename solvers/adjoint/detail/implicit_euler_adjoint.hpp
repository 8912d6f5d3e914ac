#pragma once
// Exact gradients through implicit_euler (docs/gradients.md): the discrete adjoint of the
// linearized backward-Euler step (or of the converged Newton step), terrain contact, contact
// between bodies and pins included with each step's active set held fixed. One forward run stores
// every step's state, velocity change and constraint set; one backward pass solves each step's
// (filtered) system again, transposed, and gathers the gradient of a loss on the states with
// respect to the springs' coefficients, the particle masses, gravity, the external forces'
// parameters, the initial state and the targets of driven pins.
#include <functional>
#include <string>
#include <vector>

#include <jelly/core/state.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

class Simulator;

// A loss term at frame k (the state after k steps; 0 = the start): returns its value and adds
// dL/dx and dL/dv (3N each, zero on entry) for that state.
using FrameLoss = std::function<Real(int frame, const State& state, VecX& dl_dx, VecX& dl_dv)>;

struct GradientProblem {
  int steps = 0;  // K >= 1 steps of the simulator's dt
  // The frames (0..K) at which `loss` is evaluated; empty: frame K only.
  std::vector<int> loss_frames;
  FrameLoss loss;
  // Pins driven by a control sequence: before step k, pinned particle driven_pins[p] is set
  // moving from where it is to pin_targets[k * P + p] within the step (Simulator::
  // set_pin_target with velocity (target - x) / dt), so that it ends step k at its target.
  std::vector<int> driven_pins;
  std::vector<Vec3> pin_targets;  // [K * P]
  // 0: every step's record is kept (x, v, dv: 9N doubles per step). S > 0: a snapshot of the
  // simulator every S steps; the backward pass runs each segment again from its snapshot and
  // keeps S steps' records at a time (one more forward run; the same result for the backends
  // that restart bit for bit: CHOLMOD, LDLT, block-Jacobi CG).
  int checkpoint_every = 0;
};

struct GradientResult {
  Real loss = 0;
  VecX initial_position;  // dL/dx0 [3N]
  VecX initial_velocity;  // dL/dv0 [3N]
  Vec3 gravity = Vec3::Zero();
  // Per body b and spring type t (SpringType), at [kSpringTypeCount * b + t]: dL/dks, dL/dkd of
  // the coefficients the body's springs of that type share (zero where it has none).
  std::vector<Real> ks, kd;
  // Per body: dL/d(the mass of each of its particles), all changed together.
  std::vector<Real> particle_mass;
  std::vector<Vec3> pin_targets;  // [K * P] as GradientProblem::pin_targets
  // Per external force e of the model (model.external_forces[e]): dL/d(its `vector`, the force in
  // N or the wind's air velocity in m/s), dL/d(drag) (wind; zero for the others) and dL/d(gust).
  std::vector<Vec3> force_vector;
  std::vector<Real> force_drag, force_gust;
  // What the backward pass held fixed: constrained particle-steps (terrain contacts, pins not
  // counted), of which sliding (the friction viscosity, which the forward step takes from the
  // previous solve's impulse, is held) and bouncing (restitution's velocity change is not
  // differentiated).
  long contact_steps = 0;
  long slide_steps = 0;
  long bounce_steps = 0;
  // Contact pairs between bodies (inside the solve, each step's active pairs held): pair-steps,
  // of which sliding with a friction viscosity (held), and bouncing (restitution after the solve,
  // held); steps whose end projected an overlap deeper than 0.5 % of the radii (held).
  long pair_steps = 0;
  long pair_slide_steps = 0;
  long pair_bounce_steps = 0;
  long pair_projected_steps = 0;
  // newton_iterations > 1: steps whose Newton iterations stopped above the tolerance (the
  // adjoint is of the converged step, so it is approximate there).
  long newton_unconverged_steps = 0;
  // projective_dynamics: the largest ratio over the steps of the residual at the step's last
  // iterate to its first (the gradient is of the converged steps; near 0 when they converged).
  Real forward_residual = 0;
  // "cholmod", "ldlt", "cg_jacobi", "cg_lagged_cholmod", "cg_jacobi_matrix_free" or (Newton)
  // "sparse_lu" (assembled, up to 1000 unknowns), "bicgstab_jacobi" (assembled, above),
  // "bicgstab_block_jacobi_matrix_free" (after a matrix-free forward); projective_dynamics:
  // "bicgstab_pd_prefactored"
  std::string backward_solver;
  // The iterations of the matrix-free backward solves (CG, BiCGSTAB), summed over the steps.
  long backward_iterations = 0;
  double forward_seconds = 0, backward_seconds = 0;
};

// Runs `simulator` (implicit_euler, from its current state) for problem.steps steps and returns
// the loss and its gradient; the simulator is left at the end of the run. The forward states are
// kept in memory (9N doubles per step: x, v, dv), or recomputed from checkpoints
// (GradientProblem::checkpoint_every). With newton_iterations > 1 each step's adjoint is that of
// its converged Newton iterate (implicit function theorem; exact Jacobian, sparse LU).
// Throws InputError for what the adjoint does not differentiate: another integrator, contact
// models other than coulomb inside the solve, contact between bodies resolved after the step,
// added forces, anchor springs, or a malformed problem; std::runtime_error when a step or a
// backward solve fails.
GradientResult implicit_euler_gradient(Simulator& simulator, const GradientProblem& problem);

}  // namespace jelly
