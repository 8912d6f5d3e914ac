#include <jelly/core/detail/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <jelly/core/detail/field_table.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

std::string json_child(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string json_element(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

std::string json_text(const Json& value) {
  constexpr std::size_t kMaxLength = 80;
  // Invalid UTF-8 (a key or text from a --set assignment or a damaged file) is shown as U+FFFD
  // instead of throwing from inside an error message.
  std::string text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
  if (text.size() > kMaxLength) text = text.substr(0, kMaxLength - 3) + "...";
  return text;
}

Real json_number(const Json& value, const std::string& path) {
  if (!value.is_number()) throw InputError(path, json_text(value), "a number");
  return value.get<Real>();
}

int json_integer(const Json& value, const std::string& path) {
  if (value.is_number_integer()) {
    const auto i = value.get<long long>();
    if (i >= std::numeric_limits<int>::min() && i <= std::numeric_limits<int>::max()) {
      return static_cast<int>(i);
    }
  } else if (value.is_number_float()) {
    const double d = value.get<double>();
    if (std::floor(d) == d && std::abs(d) < 2e9) return static_cast<int>(d);
  }
  throw InputError(path, json_text(value), "an integer");
}

long long json_long(const Json& value, const std::string& path) {
  if (value.is_number_integer()) {
    if (value.is_number_unsigned() &&
        value.get<unsigned long long>() >
            static_cast<unsigned long long>(std::numeric_limits<long long>::max())) {
      throw InputError(path, json_text(value), "an integer below 2^63");
    }
    return value.get<long long>();
  }
  if (value.is_number_float()) {
    const double d = value.get<double>();
    if (std::floor(d) == d && std::abs(d) < 9e18) return static_cast<long long>(d);
  }
  throw InputError(path, json_text(value), "an integer");
}

Vec3 json_vec3(const Json& value, const std::string& path) {
  if (!value.is_array() || value.size() != 3 ||
      !std::all_of(value.begin(), value.end(), [](const Json& c) { return c.is_number(); })) {
    throw InputError(path, json_text(value), "an array of 3 numbers [x, y, z]");
  }
  return Vec3(value[0].get<Real>(), value[1].get<Real>(), value[2].get<Real>());
}

JsonFields::JsonFields(const Json& object, std::string path)
    : object_(object), path_(std::move(path)) {
  if (!object_.is_object()) {
    throw InputError(path_.empty() ? "scene" : path_, json_text(object_), "a JSON object {...}");
  }
}

bool JsonFields::has(std::string_view key) const { return object_.contains(std::string(key)); }

std::string JsonFields::path(std::string_view key) const { return json_child(path_, key); }

const Json* JsonFields::find(std::string_view key) {
  known_.emplace_back(key);
  const auto it = object_.find(std::string(key));
  return it == object_.end() ? nullptr : &*it;
}

void JsonFields::missing(std::string_view key) const {
  throw InputError(path(key) + " is missing: it is required");
}

Real JsonFields::number(std::string_view key) {
  const Json* v = find(key);
  if (v == nullptr) missing(key);
  return json_number(*v, path(key));
}

Real JsonFields::number_or(std::string_view key, Real fallback) {
  const Json* v = find(key);
  return v == nullptr ? fallback : json_number(*v, path(key));
}

int JsonFields::integer_or(std::string_view key, int fallback) {
  const Json* v = find(key);
  return v == nullptr ? fallback : json_integer(*v, path(key));
}

long long JsonFields::long_or(std::string_view key, long long fallback) {
  const Json* v = find(key);
  return v == nullptr ? fallback : json_long(*v, path(key));
}

bool JsonFields::boolean_or(std::string_view key, bool fallback) {
  const Json* v = find(key);
  if (v == nullptr) return fallback;
  if (!v->is_boolean()) throw InputError(path(key), json_text(*v), "true or false");
  return v->get<bool>();
}

std::string JsonFields::string(std::string_view key) {
  const Json* v = find(key);
  if (v == nullptr) missing(key);
  if (!v->is_string()) throw InputError(path(key), json_text(*v), "a string");
  return v->get<std::string>();
}

std::string JsonFields::string_or(std::string_view key, const std::string& fallback) {
  if (has(key)) return string(key);
  known_.emplace_back(key);
  return fallback;
}

Vec3 JsonFields::vec3_or(std::string_view key, const Vec3& fallback) {
  const Json* v = find(key);
  return v == nullptr ? fallback : json_vec3(*v, path(key));
}

std::string JsonFields::file(std::string_view key) {
  const std::string name = string(key);
  if (name.empty()) throw InputError(path(key), "\"\"", "a file name");
  std::filesystem::path p(name);
  if (p.is_relative() && !base_directory_.empty()) p = std::filesystem::path(base_directory_) / p;
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(p, ec);
  return (ec ? p : absolute).lexically_normal().string();
}

const Json* JsonFields::value(std::string_view key) { return find(key); }

void JsonFields::reject_unknown() const {
  for (auto it = object_.begin(); it != object_.end(); ++it) {
    if (std::find(known_.begin(), known_.end(), it.key()) != known_.end()) continue;
    std::string allowed;
    for (const std::string& k : known_) {
      if (allowed.find("\"" + k + "\"") != std::string::npos) continue;
      allowed += (allowed.empty() ? "" : ", ") + ("\"" + k + "\"");
    }
    throw InputError(path(it.key()), json_text(it.value()),
                     "unknown key; allowed here: " + (allowed.empty() ? "none" : allowed));
  }
}

Json json_of(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

// The helpers of the field tables' factories (core/detail/field_table.hpp).
std::string_view field_type_name(FieldType type) {
  switch (type) {
    case FieldType::kInteger:
      return "integer";
    case FieldType::kNumber:
      return "number";
    case FieldType::kBoolean:
      return "boolean";
    case FieldType::kString:
      return "string";
    case FieldType::kChoice:
      return "choice";
    case FieldType::kVec3:
      return "vec3";
    case FieldType::kObject:
      return "object";
    case FieldType::kList:
      return "list";
    case FieldType::kFile:
      return "file";
  }
  return "unknown";
}

int json_field_integer(JsonFields& f, std::string_view key, int fallback) {
  return f.integer_or(key, fallback);
}
long long json_field_long(JsonFields& f, std::string_view key, long long fallback) {
  return f.long_or(key, fallback);
}
Real json_field_number(JsonFields& f, std::string_view key, Real fallback) {
  return f.number_or(key, fallback);
}
bool json_field_boolean(JsonFields& f, std::string_view key, bool fallback) {
  return f.boolean_or(key, fallback);
}
std::string json_field_string(JsonFields& f, std::string_view key, const std::string& fallback) {
  return f.string_or(key, fallback);
}
Vec3 json_field_vec3(JsonFields& f, std::string_view key, const Vec3& fallback) {
  return f.vec3_or(key, fallback);
}
std::string json_field_path(const JsonFields& f, std::string_view key) { return f.path(key); }
const Json* json_field_value(JsonFields& f, std::string_view key) { return f.value(key); }
std::string json_field_file(JsonFields& f, std::string_view key) {
  // An empty name is left to the row's check, whose message says what file it takes.
  const Json* v = f.value(key);
  if (v != nullptr && v->is_string() && v->get<std::string>().empty()) return "";
  return f.file(key);
}
void json_field_require(JsonFields& f, std::string_view key) {
  if (f.value(key) == nullptr) throw InputError(f.path(key) + " is missing: it is required");
}
Real json_field_number_or_inf(JsonFields& f, std::string_view key, Real fallback) {
  const Json* v = f.value(key);
  if (v == nullptr) return fallback;
  if (v->is_string() && v->get<std::string>() == "inf")
    return std::numeric_limits<Real>::infinity();
  if (!v->is_number()) throw InputError(f.path(key), json_text(*v), "a number or \"inf\"");
  return v->get<Real>();
}
bool json_field_has(const JsonFields& f, std::string_view key) { return f.has(key); }
void json_field_reject_unknown(const JsonFields& f) { f.reject_unknown(); }

void json_field_put(Json& out, std::string_view key, long long value) {
  out[std::string(key)] = value;
}
void json_field_put(Json& out, std::string_view key, Real value) { out[std::string(key)] = value; }
void json_field_put(Json& out, std::string_view key, bool value) { out[std::string(key)] = value; }
void json_field_put(Json& out, std::string_view key, const std::string& value) {
  out[std::string(key)] = value;
}
void json_field_put(Json& out, std::string_view key, const Vec3& value) {
  out[std::string(key)] = json_of(value);
}
void json_field_put_or_inf(Json& out, std::string_view key, Real value) {
  out[std::string(key)] = std::isinf(value) && value > 0 ? Json("inf") : Json(value);
}
void json_field_put_json(Json& out, std::string_view key, const Json& value) {
  out[std::string(key)] = value;
}

// As require() shows values (errors.hpp), so that messages read as before the tables.
std::string json_field_text(long long value) { return to_text(value); }
std::string json_field_text(Real value) { return to_text(value); }
std::string json_field_text(bool value) { return value ? "true" : "false"; }
std::string json_field_text(const std::string& value) { return "\"" + value + "\""; }
std::string json_field_text(const Vec3& value) { return to_text(value.transpose()); }

std::string json_field_dump(const std::function<void(Json&)>& write, std::string_view key) {
  Json out = Json::object();
  write(out);
  return out[std::string(key)].dump();
}

std::vector<FieldTableDocument>& component_field_documents() {
  static std::vector<FieldTableDocument> documents;
  return documents;
}

}  // namespace jelly
