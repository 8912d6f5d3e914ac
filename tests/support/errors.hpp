#pragma once
// The message of a jelly::InputError, for the tests of bad input.
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly::testing {

// The InputError message `f` throws, or "" when it throws none.
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace jelly::testing
