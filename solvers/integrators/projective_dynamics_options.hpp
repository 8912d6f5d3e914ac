#pragma once
// Options of the projective dynamics integrator (docs/realtime.md).
#include <string>

#include <jelly/core/json.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct ProjectiveDynamicsOptions {
  // Local/global iterations per step (one force evaluation and one prefactored solve each).
  int iterations = 10;
  // > 0: stop earlier once the residual |f - M (v1 - v0) / h| has dropped to this fraction of
  // the residual of the step's first iterate; 0: always run `iterations`.
  Real tolerance = 0;
  // Chebyshev semi-iterative acceleration (Wang 2015) of the iterations.
  bool chebyshev = false;
  // Spectral radius of the plain iteration, in [0, 1); 0 = measured during the first step.
  Real chebyshev_rho = 0;
  // Under-relaxation gamma of the accelerated update, in (0, 1].
  Real chebyshev_gamma = 0.9;
  // Plain iterations of each step before the acceleration starts (Wang's S).
  int chebyshev_delay = 2;
  // How coulomb terrains enter the step: "projection" (inside the iterations: contact particles
  // kept on the surface, their inward residual taken by the contact, Coulomb friction) or
  // "after_step" (the explicit integrators' resolve after the step).
  std::string contact = "projection";
  // Fill-reducing ordering of the CHOLMOD factor: "metis", "amd", "nesdis" or "best".
  std::string ordering = "metis";

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of projective_dynamics; validated with the fields' JSON path.
  static ProjectiveDynamicsOptions read(JsonFields& fields);
  Json to_json() const;
};

}  // namespace jelly
