#include <jelly/geometry/detail/mesh_file.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>
#include <vector>

#include <jelly/core/detail/input_file.hpp>
#include <jelly/core/errors.hpp>

namespace jelly::detail {

namespace {

constexpr std::uintmax_t kMaxMeshFileBytes = 1ull << 30;

// Throws InputError(field, value, ...) at the first control character of `text` other than tab,
// line and page breaks.
void require_no_control_characters(const std::string& text, const std::string& field,
                                   const std::string& value, const std::string& format) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\v' && c != '\f' && c != '\r') {
      char byte[8];
      std::snprintf(byte, sizeof byte, "0x%02x", c);
      throw InputError(field, value,
                       "a text " + format + " file (byte " + std::to_string(i) + " is " + byte +
                           ", a control character no " + format + " file holds)");
    }
  }
}

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

void require_text_mesh(const std::string& path, const std::string& field, const std::string& value,
                       const std::string& format) {
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (format == "STL") {
    // A binary STL file (which may begin with "solid" too) has exactly 84 + 50 n bytes.
    if (text.compare(0, 5, "solid") != 0) return;
    if (text.size() >= 84) {
      std::uint32_t n = 0;
      for (int k = 3; k >= 0; --k) n = n << 8 | static_cast<unsigned char>(text[80 + k]);
      if (text.size() == 84 + 50 * static_cast<std::uint64_t>(n)) return;
    }
  }
  require_no_control_characters(text, field, value, format);
}

namespace {

struct Property {
  int size = 0;        // bytes of a scalar, or of a list's items
  int count_size = 0;  // bytes of a list's length; 0 for a scalar
  bool count_signed = false;
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
};

// Bytes of a PLY scalar type, 0 for an unknown one; `is_signed` tells a signed integer.
int type_size(const std::string& type, bool* is_signed = nullptr) {
  static const struct {
    const char* name;
    int size;
    bool is_signed;
  } kTypes[] = {
      {"char", 1, true},  {"int8", 1, true},    {"uchar", 1, false},  {"uint8", 1, false},
      {"short", 2, true}, {"int16", 2, true},   {"ushort", 2, false}, {"uint16", 2, false},
      {"int", 4, true},   {"int32", 4, true},   {"uint", 4, false},   {"uint32", 4, false},
      {"float", 4, true}, {"float32", 4, true}, {"double", 8, true},  {"float64", 8, true}};
  for (const auto& t : kTypes) {
    if (type == t.name) {
      if (is_signed != nullptr) *is_signed = t.is_signed;
      return t.size;
    }
  }
  return 0;
}

// A list length stored in `bytes` bytes at p (little or big endian), as a signed number.
long long read_count(const char* p, int bytes, bool is_signed, bool big_endian) {
  std::uint64_t u = 0;
  for (int k = 0; k < bytes; ++k) {
    const auto byte = static_cast<unsigned char>(p[big_endian ? k : bytes - 1 - k]);
    u = (u << 8) | byte;
  }
  if (is_signed && bytes < 8 && (u >> (8 * bytes - 1)) != 0) {
    return static_cast<long long>(u) - (1LL << (8 * bytes));  // negative
  }
  return static_cast<long long>(u);
}

}  // namespace

void require_ply_counts_fit(const std::string& path, const std::string& field,
                            const std::string& value) {
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto fail = [&](const std::string& why) {
    throw InputError(field, value, "a PLY file whose counts fit in it (" + why + ")");
  };
  // What the walk cannot follow is refused here: assimp's PLY reader reads past its buffer on
  // a header it misparses (issue 44, found by jelly_mesh_fuzzer).
  const auto malformed = [&](const std::string& why) {
    throw InputError(field, value, "a well-formed PLY file (" + why + ")");
  };

  // The header: lines up to the line "end_header".
  std::size_t pos = 0;
  std::vector<std::string> lines;
  bool ended = false;
  while (pos < text.size() && !ended) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = std::min(end + 1, text.size());
    ended = line == "end_header";
    if (!ended) lines.push_back(std::move(line));
  }
  if (lines.empty() || lines[0] != "ply") malformed("the first line is not \"ply\"");
  if (!ended) malformed("no line \"end_header\" ends its header");
  std::string format;
  std::vector<Element> elements;
  for (std::size_t l = 1; l < lines.size(); ++l) {
    const std::string& line = lines[l];
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "format") {
      std::string version;
      words >> format >> version;
      if (version != "1.0") malformed("format version '" + version + "', not 1.0");
    } else if (key == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      const auto [end, error] = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (error != std::errc() || end != count.data() + count.size() || e.count < 0 ||
          e.count > static_cast<long long>(text.size())) {
        fail("its header says element " + e.name + " " + count + "; the file has " +
             std::to_string(text.size()) + " bytes");
      }
      elements.push_back(std::move(e));
    } else if (key == "property") {
      if (elements.empty()) fail("a property before any element");
      std::string type;
      words >> type;
      Property p;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        p.count_size = type_size(count_type, &p.count_signed);
        p.size = type_size(item_type);
        if (p.count_size == 0 || p.size == 0) {
          fail("a list of unknown type '" + count_type + " " + item_type + "'");
        }
      } else {
        p.size = type_size(type);
        if (p.size == 0) fail("a property of unknown type '" + type + "'");
      }
      elements.back().properties.push_back(p);
    } else if (key != "comment" && key != "obj_info" && !key.empty()) {
      malformed("header line " + std::to_string(l + 1) + " starts with '" + key +
                "', not format, element, property, comment or obj_info");
    }
  }

  // The body: each list's length against what is left.
  const bool ascii = format == "ascii";
  const bool big_endian = format == "binary_big_endian";
  if (!ascii && !big_endian && format != "binary_little_endian") {
    malformed("format '" + format + "', not ascii, binary_little_endian or binary_big_endian");
  }
  // An ASCII body is text: a NUL byte in a vertex line made assimp's reader lose its count of the
  // faces and abort on an assertion (jelly_mesh_fuzzer; the input is in tests/fuzz/corpus/mesh).
  if (ascii) require_no_control_characters(text, field, value, "PLY");
  // An ASCII element is one line, as assimp reads it: its words never cross a line break, and
  // its line holds nothing after them (a line read one way by this walk and another by assimp
  // made assimp take a number for a count and allocate its size; jelly_mesh_fuzzer).
  const auto blank = [&](std::size_t at) {
    return at < text.size() && text[at] != '\n' &&
           std::isspace(static_cast<unsigned char>(text[at]));
  };
  const auto next_word = [&](std::string_view* word) {
    while (blank(pos)) ++pos;
    const std::size_t start = pos;
    while (pos < text.size() && !std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    *word = std::string_view(text).substr(start, pos - start);
    return !word->empty();
  };
  const auto truncated = [&](const Element& e, long long i) {
    malformed("it ends inside element " + e.name + " " + std::to_string(i) + " of " +
              std::to_string(e.count));
  };
  for (const Element& e : elements) {
    for (long long i = 0; i < e.count; ++i) {
      if (ascii) {  // the element's line (blank lines between elements pass)
        while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
      }
      for (const Property& p : e.properties) {
        long long items = 1;
        if (p.count_size > 0) {
          if (ascii) {
            std::string_view word;
            if (!next_word(&word)) truncated(e, i);
            double length = 0;
            const auto [end, error] =
                std::from_chars(word.data(), word.data() + word.size(), length);
            if (error != std::errc() || end != word.data() + word.size() ||
                length != std::floor(length)) {
              malformed("element " + e.name + " " + std::to_string(i) + " has a list length '" +
                        std::string(word) + "', not a whole number");
            }
            if (!(length >= 0 && length <= static_cast<double>(text.size() - pos) / 2 + 1)) {
              fail("element " + e.name + " " + std::to_string(i) + " has a list of " +
                   std::string(word) + " items, more than the " +
                   std::to_string(text.size() - pos) + " bytes left can hold");
            }
            items = static_cast<long long>(length);
          } else {
            if (pos + p.count_size > text.size()) truncated(e, i);
            items = read_count(text.data() + pos, p.count_size, p.count_signed, big_endian);
            pos += p.count_size;
            if (items < 0 || static_cast<unsigned long long>(items) * p.size > text.size() - pos) {
              fail("element " + e.name + " " + std::to_string(i) + " has a list of " +
                   std::to_string(items) + " items, more than the " +
                   std::to_string(text.size() - pos) + " bytes left can hold");
            }
          }
        }
        // A face of fewer than 3 vertices is no polygon: assimp's triangulation aborts on one of
        // none (an assertion in the Debian build; issue 44, jelly_mesh_fuzzer).
        if (p.count_size > 0 && e.name == "face" && items < 3) {
          malformed("element face " + std::to_string(i) + " has a list of " +
                    std::to_string(items) + " vertices; a face has at least 3");
        }
        if (ascii) {
          std::string_view word;
          for (long long k = 0; k < items; ++k) {
            if (!next_word(&word)) truncated(e, i);
          }
        } else {
          if (static_cast<unsigned long long>(items) * p.size > text.size() - pos) truncated(e, i);
          pos += static_cast<std::size_t>(items) * p.size;
        }
      }
      if (ascii) {
        while (blank(pos)) ++pos;
        if (pos < text.size() && text[pos] != '\n') {
          malformed("element " + e.name + " " + std::to_string(i) +
                    " has more on its line than its properties");
        }
      }
    }
  }
}

}  // namespace jelly::detail
