#pragma once
// The one convention for named choices (as Ceres' types.h): each enum has one table of its
// values with their names and one-line descriptions, read in both directions by these helpers.
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/errors.hpp>

namespace jelly {

template <typename E>
struct EnumName {
  E value;
  std::string_view name;
  std::string_view description;
};

// The names of a table as `"a", "b", "c"` (for messages).
template <typename E>
std::string quoted_names(const std::vector<EnumName<E>>& table) {
  std::string out;
  for (const EnumName<E>& e : table)
    out += (out.empty() ? "\"" : ", \"") + std::string(e.name) + "\"";
  return out;
}

template <typename E>
std::string_view name_of(const std::vector<EnumName<E>>& table, E value) {
  for (const EnumName<E>& e : table) {
    if (e.value == value) return e.name;
  }
  return "unknown";
}

// Throws InputError "<field> = "<name>" is invalid: one of ..." for a name not in the table.
template <typename E>
E value_of(const std::vector<EnumName<E>>& table, std::string_view name, std::string_view field) {
  for (const EnumName<E>& e : table) {
    if (e.name == name) return e.value;
  }
  throw InputError(field, "\"" + std::string(name) + "\"", "one of " + quoted_names(table));
}

}  // namespace jelly
