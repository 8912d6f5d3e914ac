#pragma once
// JSON as jelly reads and writes it (nlohmann's ordered_json) and the strict reading of one
// object: typed fields with defaults or required, every key the caller reads is known, any
// other key is an InputError naming its JSON path. Every kind of the registries (body kinds,
// terrain kinds, integrator options) reads and writes itself with these.
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

// "a.b" + "c" -> "a.b.c"; "" + "c" -> "c".
std::string json_child(const std::string& path, std::string_view key);
// "terrains" + 0 -> "terrains[0]".
std::string json_element(const std::string& path, std::size_t index);
// A JSON value as it appears in messages: compact, long values cut short.
std::string json_text(const Json& value);

class JsonFields {
 public:
  // Throws InputError unless `object` is a JSON object; `path` is its JSON path ("" = root).
  JsonFields(const Json& object, std::string path);

  bool has(std::string_view key) const;
  // The JSON path of a key of this object.
  std::string path(std::string_view key) const;
  const std::string& path() const { return path_; }
  // The path as a prefix of its keys' paths: "terrains[0]." ("" at the root).
  std::string prefix() const { return path_.empty() ? std::string() : path_ + "."; }

  // Each getter marks `key` as known. The `_or` variants return `fallback` for a missing key;
  // the others throw InputError "<path> is required".
  Real number(std::string_view key);
  Real number_or(std::string_view key, Real fallback);
  int integer_or(std::string_view key, int fallback);
  long long long_or(std::string_view key, long long fallback);
  bool boolean_or(std::string_view key, bool fallback);
  std::string string(std::string_view key);
  std::string string_or(std::string_view key, const std::string& fallback);
  Vec3 vec3_or(std::string_view key, const Vec3& fallback);
  // A required file name, resolved against base_directory() when relative and returned as an
  // absolute, normalised path (the scene file's folder for a mesh named in a scene).
  std::string file(std::string_view key);
  // A sub-object or array, or nullptr when the key is missing.
  const Json* value(std::string_view key);

  // Throws InputError for the first key no getter asked for, listing the allowed keys.
  void reject_unknown() const;

  // The folder file() resolves relative names against; "" = the current directory.
  void set_base_directory(std::string directory) { base_directory_ = std::move(directory); }
  const std::string& base_directory() const { return base_directory_; }

 private:
  const Json* find(std::string_view key);
  [[noreturn]] void missing(std::string_view key) const;

  const Json& object_;
  std::string path_;
  std::vector<std::string> known_;
  std::string base_directory_;
};

// Typed conversions of a single value at `path`; throw InputError naming path, value and type.
Real json_number(const Json& value, const std::string& path);
int json_integer(const Json& value, const std::string& path);
long long json_long(const Json& value, const std::string& path);
Vec3 json_vec3(const Json& value, const std::string& path);
// A vector as a JSON array [x, y, z].
Json json_of(const Vec3& v);

}  // namespace jelly
