#pragma once
// Errors raised for bad user input: the message names the field, the value and what is allowed.
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace jelly {

class InputError : public std::invalid_argument {
 public:
  explicit InputError(const std::string& message) : std::invalid_argument(message) {}
  // "<field> = <value> is invalid: <allowed>".
  InputError(std::string_view field, std::string_view value, std::string_view allowed);
};

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
