#include <jelly/io/detail/json_parse.hpp>

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include <jelly/core/detail/input_file.hpp>
#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>

namespace jelly::detail {

namespace {

// Follows the parser's events to know the JSON path of the value being read, the keys already
// seen in each open object, and the nesting depth.
class Tracker {
 public:
  Tracker(std::string source, int max_depth) : source_(std::move(source)), max_depth_(max_depth) {}

  bool on_event(int depth, Json::parse_event_t event, const Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        if (depth >= max_depth_) {
          std::string at = where();
          if (at.size() > 60) at = at.substr(0, 57) + "...";
          fail("it nests arrays and objects deeper than " + std::to_string(max_depth_) +
               " levels at " + (at.empty() ? std::string("the top") : at) + " (a scene needs 4)");
        }
        frames_.push_back({event == Json::parse_event_t::array_start, 0, {}, {}, where()});
        break;
      case Json::parse_event_t::key: {
        Frame& f = frames_.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second) {
          fail("the key \"" + f.key + "\" appears twice in " +
               (f.path.empty() ? std::string("the top-level object") : f.path) +
               " (only one value could count: remove the other)");
        }
        break;
      }
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        frames_.pop_back();
        element_done();
        break;
      case Json::parse_event_t::value:
        element_done();
        break;
    }
    return true;
  }

  // The JSON path of the value being read ("" at the top).
  std::string where() const {
    if (frames_.empty()) return "";
    const Frame& f = frames_.back();
    return f.array ? json_element(f.path, f.index) : json_child(f.path, f.key);
  }

  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(source_ + " is not valid JSON: " + why);
  }

 private:
  struct Frame {
    bool array = false;
    std::size_t index = 0;  // arrays: of the element being read
    std::string key;        // objects: of the value being read
    std::set<std::string> keys;
    std::string path;  // of this array or object
  };

  void element_done() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  std::string source_;
  int max_depth_;
  std::vector<Frame> frames_;
};

// "[json.exception.parse_error.101] parse error at ..." -> "parse error at ...".
std::string library_message(const Json::exception& e) {
  std::string why = e.what();
  const std::size_t bracket = why.find("] ");
  if (why.rfind("[json.exception", 0) == 0 && bracket != std::string::npos) {
    why = why.substr(bracket + 2);
  }
  return why;
}

// Parses with `tracker` watching; returns false for text that is not JSON when `if_json`.
bool parse(const std::string& text, Tracker& tracker, bool if_json, Json* out) {
  try {
    Json j = Json::parse(
        text,
        [&tracker](int depth, Json::parse_event_t event, Json& parsed) {
          return tracker.on_event(depth, event, parsed);
        },
        /*allow_exceptions=*/true, /*ignore_comments=*/true);
    *out = std::move(j);
    return true;
  } catch (const Json::parse_error& e) {
    if (if_json) return false;
    tracker.fail(library_message(e));
  } catch (const Json::exception& e) {
    // A number outside a double's range (out_of_range.406) and anything else the library
    // reports about text that is otherwise JSON.
    const std::string at = tracker.where();
    tracker.fail(library_message(e) + (at.empty() ? "" : " at " + at) +
                 " (numbers must be within a double's range, about +-1.8e308)");
  }
}

}  // namespace

Json parse_json(const std::string& text, const std::string& source, int max_depth) {
  Tracker tracker(source, max_depth);
  Json j;
  parse(text, tracker, /*if_json=*/false, &j);
  return j;
}

bool parse_json_if_json(const std::string& text, const std::string& source, Json* out,
                        int max_depth) {
  Tracker tracker(source, max_depth);
  return parse(text, tracker, /*if_json=*/true, out);
}

std::string read_json_file(const std::string& path, const std::string& what) {
  const auto fail = [&](const std::string& why) {
    return InputError("cannot read the " + what + " '" + path + "': " + why);
  };
  if (const std::string why = why_not_a_regular_file(path); !why.empty()) throw fail(why);
  struct stat info {};
  if (stat(path.c_str(), &info) != 0) throw fail(std::strerror(errno));
  if (info.st_size > kMaxJsonFileBytes) {
    throw fail("it holds " + std::to_string(info.st_size) + " bytes, more than a JSON file can (" +
               std::to_string(kMaxJsonFileBytes) + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw fail(std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw fail("a read error");
  return text.str();
}

}  // namespace jelly::detail
