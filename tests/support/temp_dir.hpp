#pragma once
// A fresh directory under the system's temporary directory, removed with the object (with what
// the test wrote into it).
#include <cstdlib>
#include <filesystem>
#include <string>

namespace jelly::testing {

class TempDir {
 public:
  // The directory's name starts with `prefix` (which tests made it, when one is left behind).
  explicit TempDir(const std::string& prefix = "jelly") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace jelly::testing
