#include <jelly/core/errors.hpp>

namespace jelly {

namespace {
std::string format_input_error(std::string_view field, std::string_view value,
                               std::string_view allowed) {
  std::string message;
  message.append(field).append(" = ").append(value).append(" is invalid: ").append(allowed);
  return message;
}
}  // namespace

InputError::InputError(std::string_view field, std::string_view value, std::string_view allowed)
    : std::invalid_argument(format_input_error(field, value, allowed)) {}

}  // namespace jelly
