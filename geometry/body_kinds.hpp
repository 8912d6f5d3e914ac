#pragma once
// Every body kind a scene can name, from one table: adding a kind is its own files (a
// BodyShape subclass and its builder) and one line there.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/geometry/body_shape.hpp>

namespace jelly {

struct BodyKindInfo {
  std::string_view name;
  std::string_view description;  // one line, with the kind's keys
  // Reads the kind's keys from `fields` (which names the JSON path), validates them and returns
  // the shape; the keys every body has (name, kind, material, pins, ...) are the caller's.
  std::unique_ptr<BodyShape> (*read)(JsonFields& fields);
};

// Sorted by name.
const std::vector<BodyKindInfo>& body_kinds();
// Throws InputError naming `field` and listing the known kinds for an unknown name.
const BodyKindInfo& find_body_kind(std::string_view name, const std::string& field);

}  // namespace jelly
