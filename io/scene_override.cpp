#include <jelly/io/detail/scene_override.hpp>

#include <cctype>
#include <vector>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {

namespace detail {

namespace {

// One step of a path: an object key, or an array index written "[i]" (an index only), or a
// bare number "terrains.0" (an index into an array, a key into an object).
struct PathStep {
  std::string key;
  bool bracketed = false;
  bool numeric = false;
  std::size_t index = 0;
};

// "--set '<assignment>'" for messages, a long one cut short.
std::string set_name(const std::string& assignment) {
  constexpr std::size_t kMaxLength = 80;
  return "--set '" +
         (assignment.size() > kMaxLength ? assignment.substr(0, kMaxLength - 3) + "..."
                                         : assignment) +
         "'";
}

bool all_digits(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

std::vector<PathStep> parse_path(const std::string& path, const std::string& assignment) {
  const auto fail = [&](const std::string& why) -> InputError {
    return InputError(set_name(assignment) + ": " + why);
  };
  std::vector<PathStep> steps;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = path.find('.', start);
    std::string segment = path.substr(start, dot == std::string::npos ? dot : dot - start);
    const std::size_t bracket = segment.find('[');
    const std::string name = segment.substr(0, bracket);
    if (name.empty() && (bracket == std::string::npos || steps.empty())) {
      throw fail("empty key in the path '" + path + "'");
    }
    if (!name.empty()) {
      const bool numeric = all_digits(name) && name.size() < 10;
      steps.push_back({name, false, numeric, numeric ? std::stoul(name) : 0});
    }
    std::size_t pos = bracket;
    while (pos != std::string::npos && pos < segment.size()) {
      const std::size_t close = segment.find(']', pos);
      const std::string inside =
          close == std::string::npos ? "" : segment.substr(pos + 1, close - pos - 1);
      if (segment[pos] != '[' || close == std::string::npos || !all_digits(inside) ||
          inside.size() >= 10) {
        throw fail("'" + segment + "' is not a key or key[index] (indices are integers >= 0)");
      }
      steps.push_back({inside, true, true, std::stoul(inside)});
      pos = close + 1;
    }
    if (steps.size() > static_cast<std::size_t>(kMaxJsonDepth / 2)) {
      throw fail("the path '" + path.substr(0, 60) + (path.size() > 60 ? "..." : "") +
                 "' has more than " + std::to_string(kMaxJsonDepth / 2) + " steps");
    }
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return steps;
}

}  // namespace

void apply_override(Json& scene, const std::string& assignment) {
  const std::size_t equals = assignment.find('=');
  if (equals == std::string::npos) {
    throw InputError(set_name(assignment) +
                     ": expected path=value, e.g. springs.structural.ks=2400");
  }
  const std::string path = assignment.substr(0, equals);
  const std::string text = assignment.substr(equals + 1);
  try {
    (void)Json(path).dump();
  } catch (const Json::exception&) {
    throw InputError(set_name(assignment) + ": the path is not valid UTF-8 text");
  }
  Json value;
  // A path and a value of at most half the nesting each keep the edited scene within it.
  if (!parse_json_if_json(text, set_name(assignment), &value, kMaxJsonDepth / 2)) {
    value = text;
    try {
      (void)value.dump();
    } catch (const Json::exception&) {
      throw InputError(set_name(assignment) + ": the value is not valid UTF-8 text");
    }
  }

  Json* current = &scene;
  std::string walked;  // the JSON path reached so far, as messages write it
  for (const PathStep& step : parse_path(path, assignment)) {
    const std::string where = walked.empty() ? "the scene" : walked;
    if (step.numeric && (step.bracketed || current->is_array())) {
      if (!current->is_array()) {
        throw InputError(set_name(assignment) + ": " + where + " is not an array");
      }
      if (step.index >= current->size()) {
        throw InputError(set_name(assignment) + ": " + json_element(walked, step.index) +
                         " does not exist (" + where + " has " + std::to_string(current->size()) +
                         (current->size() == 1 ? " element)" : " elements)"));
      }
      current = &(*current)[step.index];
      walked = json_element(walked, step.index);
      continue;
    }
    if (current->is_null()) *current = Json::object();
    if (!current->is_object()) {
      throw InputError(set_name(assignment) + ": " + where + " is " + json_text(*current) +
                       ", not an object with a key \"" + step.key + "\"");
    }
    current = &(*current)[step.key];
    walked = json_child(walked, step.key);
  }
  *current = std::move(value);
}

}  // namespace detail

std::string apply_override(const std::string& json_text, const std::string& assignment) {
  Json scene = detail::parse_json(json_text, "apply_override: the scene text");
  detail::apply_override(scene, assignment);
  return scene.dump(2);
}

}  // namespace jelly
