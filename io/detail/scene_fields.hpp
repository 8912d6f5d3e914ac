#pragma once
// The field tables of a scene's top level and its integrator object
// (core/detail/field_table.hpp), declared in io/scene_json.cpp. Bodies, terrains, body contact,
// the integrator's options, divergence and crush are rows of kind object or list: their own
// tables (and the kinds' registries) read them.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {

const FieldTable<Scene>& scene_fields();
const FieldTable<IntegratorSpec>& integrator_spec_fields();

}  // namespace jelly
