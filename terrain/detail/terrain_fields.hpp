#pragma once
// The field tables of terrain kinds' specs (core/detail/field_table.hpp), declared in their
// .cpp files. Each table holds the kind's own keys; `kind` and `contact` are read by
// terrain_kinds.cpp.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {

const FieldTable<PlaneSpec>& plane_fields();  // terrain/plane.cpp
const FieldTable<SlopeSpec>& slope_fields();  // terrain/plane.cpp

}  // namespace jelly
