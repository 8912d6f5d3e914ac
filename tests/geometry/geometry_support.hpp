#pragma once
// Helpers shared by the geometry tests: temporary folders, files, meshes with known answers.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/triangle_mesh.hpp>

#include "support/temp_dir.hpp"

namespace jelly::testing {

inline std::string write_text(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

// The message of the InputError `f` throws ("" and a test failure when it throws none).
template <typename F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

// The number of occupied cells of a lattice grid.
inline int occupied(const LatticeGrid& grid) {
  int n = 0;
  for (char c : grid.occupied) n += c;
  return n;
}

}  // namespace jelly::testing
