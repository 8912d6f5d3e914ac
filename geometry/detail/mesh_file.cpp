#include <jelly/geometry/detail/mesh_file.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>

#include <jelly/core/detail/input_file.hpp>
#include <jelly/core/errors.hpp>

namespace jelly::detail {

namespace {
constexpr std::uintmax_t kMaxMeshFileBytes = 1ull << 30;
}  // namespace

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void require_mesh_file(const std::string& path, const std::string& field,
                       const std::string& value) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  require(fs::exists(status), field, value, "an existing mesh file (not found: " + path + ")");
  const std::string why = why_not_a_regular_file(path);
  require(why.empty(), field, value, "a regular file (" + path + ": " + why + ")");
  const std::uintmax_t bytes = fs::file_size(path, ec);
  require(!ec && bytes <= kMaxMeshFileBytes, field, value,
          "a mesh file of at most 1 GiB (this one has " + std::to_string(bytes) + " bytes)");
  require(static_cast<bool>(std::ifstream(path)), field, value, "a readable file");
}

}  // namespace jelly::detail
