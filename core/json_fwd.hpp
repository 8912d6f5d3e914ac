#pragma once
// The names of jelly's JSON types without their definitions: all a header needs to declare a
// function that reads or writes JSON (core/detail/json.hpp says what they are). Keeping nlohmann's
// definitions out of the headers keeps them cheap to compile; a source that builds or reads
// JSON includes core/detail/json.hpp.
#include <nlohmann/json_fwd.hpp>

namespace jelly {

// Ordered, so that written scenes keep the order of the format (cube, springs, ...).
using Json = nlohmann::ordered_json;
class JsonFields;

}  // namespace jelly
