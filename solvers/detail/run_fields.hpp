#pragma once
// The field tables of a run's settings (core/detail/field_table.hpp): the scene's divergence and
// crush objects (divergence_guard.cpp, run_report.cpp) and SimulatorOptions
// (simulator_options.cpp). The row factories declare the keys a scene and SimulatorOptions
// share once (a scene holds dt under integrator, the others at its top).
#include <jelly/core/detail/field_table.hpp>
#include <jelly/solvers/run_report.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

// max_speed and max_distance (max_energy is not a scene key: the table's check validates it).
const FieldTable<DivergenceGuard>& divergence_fields();
const FieldTable<CrushLimits>& crush_fields();
// dt, output_interval, threads, divergence, crush; messages name their scene keys.
const FieldTable<SimulatorOptions>& simulator_options_fields();

template <auto... Ms>
Field<field_detail::StructOf<Ms...>> time_step_field() {
  return number_field<Ms...>("dt", "s", range_above(0), "a finite time step > 0 s",
                             "Time step (adaptive methods: the first and largest)");
}
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> output_interval_field() {
  return number_field<Ms...>("output_interval", "s", range_at_least(0),
                             "a finite interval >= 0 s (0 = every step)",
                             "Time between recorded frames; 0 = every step");
}
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> threads_field() {
  return integer_field<Ms...>("threads", "", range_at_least(0), "an integer >= 0 (0 = all cores)",
                              "Threads for forces, solves and contact (0 = chosen per step); "
                              "results are the same for any number");
}

}  // namespace jelly
