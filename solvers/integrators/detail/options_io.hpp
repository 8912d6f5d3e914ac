#pragma once
// The registry entry's options of an integrator whose options are one member of
// IntegratorOptions with read/to_json/validate of their own: for the table in registry.cpp and
// the components' registrations. Include <jelly/core/detail/json.hpp> before it.
#include <string>
#include <type_traits>
#include <utility>

#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::detail {

// The options member `Member` of IntegratorOptions, read, written and validated by its own type.
template <auto Member>
IntegratorOptionsIo options_io() {
  using Options = std::remove_reference_t<decltype(std::declval<IntegratorOptions&>().*Member)>;
  IntegratorOptionsIo io;
  io.read = [](JsonFields& f, IntegratorOptions& o) { o.*Member = Options::read(f); };
  io.write = [](const IntegratorOptions& o) { return (o.*Member).to_json(); };
  io.validate = [](const IntegratorOptions& o, const std::string& prefix) {
    (o.*Member).validate(prefix);
  };
  return io;
}

}  // namespace jelly::detail
