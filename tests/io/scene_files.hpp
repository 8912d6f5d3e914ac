#pragma once
// The scene files the project ships (scenes/), for the scene tests.
#include <string>

namespace jelly::testing {

// The path of the shipped scene file `name` (JELLY_SCENES_DIR: the target's definition).
inline std::string scene_path(const std::string& name) {
  return std::string(JELLY_SCENES_DIR) + "/" + name;
}

}  // namespace jelly::testing
