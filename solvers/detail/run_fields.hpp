#pragma once
// The field tables of a run's limits (core/detail/field_table.hpp): the scene's divergence and
// crush objects, declared in divergence_guard.cpp and run_report.cpp.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/solvers/run_report.hpp>

namespace jelly {

// max_speed and max_distance (max_energy is not a scene key: the table's check validates it).
const FieldTable<DivergenceGuard>& divergence_fields();
const FieldTable<CrushLimits>& crush_fields();

}  // namespace jelly
