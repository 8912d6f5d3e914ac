#pragma once
// Errors raised for bad user input: the message names the field, the value and what is allowed.
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace jelly {

// Bad user input (a scene, an option, an argument): the message names the field, the value and
// what is allowed. The CLI prints it and exits 2.
class InputError : public std::invalid_argument {
 public:
  // Any message.
  explicit InputError(const std::string& message) : std::invalid_argument(message) {}
  // "<field> = <value> is invalid: <allowed>".
  InputError(std::string_view field, std::string_view value, std::string_view allowed);
};

// A value as message text (doubles with 17 digits: the value read back is the value).
template <typename T>
std::string to_text(const T& value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

// Throws InputError naming field, value and what is allowed unless `ok`.
template <typename T>
void require(bool ok, std::string_view field, const T& value, std::string_view allowed) {
  if (!ok) throw InputError(field, to_text(value), allowed);
}

}  // namespace jelly

// The one convention for named choices (as Ceres' types.h): each enum has one table of its
// values with their names and one-line descriptions, read in both directions by these helpers.
namespace jelly {

template <typename E>
// One row of an enum's table: a value, its name and what it means.
struct EnumName {
  E value;                       // the enum's value
  std::string_view name;         // its name in files, options and messages
  std::string_view description;  // one line of help
};

// The names of a table as `"a", "b", "c"` (for messages).
template <typename E>
std::string quoted_names(const std::vector<EnumName<E>>& table) {
  std::string out;
  for (const EnumName<E>& e : table)
    out += (out.empty() ? "\"" : ", \"") + std::string(e.name) + "\"";
  return out;
}

// The name of `value` in `table`, or "unknown".
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
