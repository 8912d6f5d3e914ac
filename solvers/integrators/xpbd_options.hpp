#pragma once
// Options of the XPBD integrator (docs/realtime.md).
#include <string>
#include <vector>

#include <jelly/core/enum_names.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>
#include <jelly/solvers/integrators/projective_dynamics_options.hpp>  // PositionContactMode

namespace jelly {

// How a sweep visits the springs.
enum class XpbdSweep {
  kJacobi,       // every spring from the same positions, mass split between a particle's springs:
                 // symmetric, momentum-conserving, the same for any thread count (the default)
  kGaussSeidel,  // one after the other in the model's order (the original scheme: a correction
                 // travels up the lattice within a sweep, but the order breaks symmetry and
                 // angular momentum; one thread)
};
const std::vector<EnumName<XpbdSweep>>& xpbd_sweeps();

struct XpbdOptions {
  // Substeps per step (Macklin et al. 2019: many small steps of one iteration each beat few
  // steps of many iterations). Three with two Jacobi sweeps each hold the seed jelly's landing
  // at 1/60 s; one substep of two did not (docs/realtime.md, "Defaults").
  int substeps = 3;
  // Sweeps over the springs (and contacts) per substep.
  int iterations = 2;
  // How a sweep visits the springs (names: xpbd_sweeps()).
  XpbdSweep sweep = XpbdSweep::kJacobi;
  // How coulomb terrains enter the step: kProjection (position constraints with friction in
  // every sweep, restitution after each substep) or kAfterStep (the explicit integrators'
  // resolve after the step). Names: position_contact_modes().
  PositionContactMode contact = PositionContactMode::kProjection;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of xpbd; validated with the fields' JSON path.
  static XpbdOptions read(JsonFields& fields);
  Json to_json() const;
};

}  // namespace jelly
