#pragma once
// Shared by the fuzz targets of file readers: the input written to a file of the fuzzing
// process's own temporary folder, since the readers take paths.
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "fuzz/fuzz_target.hpp"

namespace jelly::fuzz {

// A folder of this process under $TMPDIR (or /tmp), made on first use; removed at exit by the
// caller's own files being overwritten input after input (the folder holds a few small files).
inline const std::string& scratch_folder() {
  static const std::string folder = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmp != nullptr && *tmp != 0 ? tmp : "/tmp") + "/jelly_fuzz_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) fail("cannot make a scratch folder " + pattern);
    return pattern;
  }();
  return folder;
}

// Writes `bytes` to `name` in the scratch folder and returns its path.
inline std::string write_scratch(const std::string& name, const std::string& bytes) {
  const std::string path = scratch_folder() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) fail("cannot write " + path);
  return path;
}

}  // namespace jelly::fuzz
