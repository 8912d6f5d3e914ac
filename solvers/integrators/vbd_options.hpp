#pragma once
// Options of the vertex block descent integrator (docs/realtime.md).
#include <string>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct VbdOptions {
  // Sweeps over all colours per step (each vertex one 3x3 Newton step per sweep).
  int iterations = 10;
  // Chebyshev semi-iterative acceleration (Wang 2015) of the sweeps with this estimate of their
  // spectral radius, in [0, 1); 0 = off.
  Real chebyshev_rho = 0;
  // Rayleigh-type damping of the paper (Chen et al. 2024, eq. 14): per vertex the force
  // -(damping / h) H_i (x_i - x_i^t), H_i its springs' local Hessian; seconds, >= 0. Added to
  // the springs' own dampers (kd), which enter every sweep exactly.
  Real damping = 0;
  // Coulomb terrains inside the sweeps (experimental): a particle below a surface at the step's
  // end has the penalty energy k d^2 / 2 (d its signed distance, < 0), k = contact_hardness
  // m_i / h^2, in its block (gradient and Hessian k n n^T), so that the springs answer the
  // contact within the step; the Simulator's contact after the step then sees no approach, so
  // that restitution and friction are lost (docs/realtime.md). 0 (default) = the Simulator's
  // contact after the step only. In [0, 1e8].
  Real contact_hardness = 0;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of vbd; validated with the fields' JSON path.
  static VbdOptions read(JsonFields& fields);
  Json to_json() const;
};

}  // namespace jelly
