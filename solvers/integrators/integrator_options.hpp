#pragma once
// Options for the integrators that take any; the explicit methods take none. Which integrator
// reads and writes which member is said by its registry entry (registry.hpp).
#include <jelly/solvers/arkode/arkode_options.hpp>
#include <jelly/solvers/integrators/implicit_euler_options.hpp>
#include <jelly/solvers/integrators/projective_dynamics_options.hpp>
#include <jelly/solvers/integrators/vbd_options.hpp>
#include <jelly/solvers/integrators/xpbd_options.hpp>

namespace jelly {

struct IntegratorOptions {
  ImplicitEulerOptions implicit;  // implicit_euler
  ArkodeOptions arkode;           // arkode_erk, arkode_dirk
  ProjectiveDynamicsOptions pd;   // projective_dynamics
  XpbdOptions xpbd;               // xpbd
  VbdOptions vbd;                 // vbd
};

}  // namespace jelly
