#pragma once
// The field table of the contact between bodies (core/detail/field_table.hpp), declared in
// solvers/contact/body_contact.cpp.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>

namespace jelly {

const FieldTable<BodyContactParams>& body_contact_fields();

}  // namespace jelly
