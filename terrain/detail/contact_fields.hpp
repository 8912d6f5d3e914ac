#pragma once
// The field table of a terrain's contact parameters (core/detail/field_table.hpp), declared in
// terrain/contact_params.cpp.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

const FieldTable<ContactParams>& contact_params_fields();

}  // namespace jelly
