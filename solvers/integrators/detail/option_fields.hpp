#pragma once
// The field tables of the integrators' options (core/detail/field_table.hpp), declared in each
// options .cpp: scene I/O, validation, the Python properties and the scene-key reference read
// them.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

const FieldTable<ArkodeOptions>& arkode_fields();  // solvers/arkode/arkode_options.cpp
const FieldTable<ImplicitEulerOptions>& implicit_euler_fields();
const FieldTable<ProjectiveDynamicsOptions>& projective_dynamics_fields();
const FieldTable<XpbdOptions>& xpbd_fields();
const FieldTable<VbdOptions>& vbd_fields();

}  // namespace jelly
