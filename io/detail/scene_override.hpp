#pragma once
// Applies "path=value" assignments (jelly run --set) to scene JSON. Internal to io/.
#include <string>

#include <jelly/core/detail/json.hpp>

namespace jelly::detail {

// See jelly::apply_override (io/scene.hpp) for the syntax. Throws InputError for an assignment
// without '=', an empty path segment, a missing array element or a path through a scalar.
void apply_override(Json& scene, const std::string& assignment);

}  // namespace jelly::detail
