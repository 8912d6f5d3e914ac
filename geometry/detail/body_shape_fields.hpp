#pragma once
// The field tables of body kinds' shapes (core/detail/field_table.hpp), declared in their .cpp
// files. Each table holds the kind's own keys; the keys every body has (material, pins,
// forces, ...) are read by body_spec.cpp.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/geometry/cube.hpp>

namespace jelly {

const FieldTable<CubeShape>& cube_shape_fields();  // geometry/cube.cpp

}  // namespace jelly
