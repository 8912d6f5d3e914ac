#pragma once
// Options of the projective dynamics integrator (docs/realtime.md): each named choice an enum
// with its name table (core/enum_names.hpp), as implicit_euler's.
#include <string>
#include <vector>

#include <jelly/core/enum_names.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>
#include <jelly/solvers/linear/cholmod_options.hpp>

namespace jelly {

// How coulomb terrains enter a step of the position-based integrators (projective_dynamics,
// xpbd).
enum class PositionContactMode {
  kProjection,  // inside the step: particles kept on the surface, Coulomb friction
  kAfterStep,   // the explicit integrators' resolve after the step
};
// "projection", "after_step".
const std::vector<EnumName<PositionContactMode>>& position_contact_modes();

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
  // How coulomb terrains enter the step: kProjection (inside the iterations: contact particles
  // kept on the surface, their inward residual taken by the contact, Coulomb friction) or
  // kAfterStep (the explicit integrators' resolve after the step).
  PositionContactMode contact = PositionContactMode::kProjection;
  // Fill-reducing ordering of the CHOLMOD factor.
  CholmodOrdering ordering = CholmodOrdering::kMetis;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of projective_dynamics; validated with the fields' JSON path.
  static ProjectiveDynamicsOptions read(JsonFields& fields);
  Json to_json() const;
};

}  // namespace jelly
