#pragma once
// Shared by the fuzz targets: a failed property aborts (the fuzzer then saves the input).
#include <cstdio>
#include <cstdlib>
#include <string>

namespace jelly::fuzz {

[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz property failed: %s\n", what.c_str());
  std::abort();
}

}  // namespace jelly::fuzz
