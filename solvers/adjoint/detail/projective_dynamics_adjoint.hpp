#pragma once
// Exact gradients through projective_dynamics (docs/gradients.md): the adjoint of each step's
// fixed point (the nonlinear backward-Euler step the local/global iterations converge to) by the
// implicit function theorem, its transposed system solved by BiCGSTAB preconditioned with the
// integrator's own prefactored matrix M + h^2 L_ks + h L_kd (DiffPD, Du et al. 2021), pins
// included. Terrains, contact between bodies, anchors and added forces are refused.
#include <string_view>

#include <jelly/solvers/adjoint/detail/implicit_euler_adjoint.hpp>

namespace jelly {

// Runs `simulator` (projective_dynamics, from its current state) for problem.steps steps and
// returns the loss and its gradient as implicit_euler_gradient does (the same problem and
// result; GradientResult::newton_unconverged_steps counts the steps whose iterations ended
// above the options' tolerance, when one is set). The gradient is that of the converged steps:
// with a fixed iteration count that stops short of convergence it differs from the derivative
// of the run as computed (GradientResult::forward_residual says by how much the last step's
// iterate missed). Throws InputError for another integrator or what is not differentiated;
// std::runtime_error when a step or a backward solve fails.
GradientResult projective_dynamics_gradient(Simulator& simulator, const GradientProblem& problem);

// The adjoint of the simulator's integrator: implicit_euler_gradient or
// projective_dynamics_gradient; InputError naming the integrator for the others.
GradientResult integrator_gradient(Simulator& simulator, const GradientProblem& problem);

// True for the integrators integrator_gradient differentiates.
bool has_adjoint(std::string_view integrator);

}  // namespace jelly
