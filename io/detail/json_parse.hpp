#pragma once
// The one entry point for JSON text read from users (scene files, --set values, the scene text
// stored in a recording): comments allowed, nesting bounded, no key twice in one object, every
// number within a double's range. Internal to io/.
#include <string>

#include <jelly/core/detail/json.hpp>

namespace jelly::detail {

// Deepest nesting of arrays and objects accepted. A scene needs 4 levels; a deeper value would
// only make the recursive parts of the JSON library (printing, copying) overflow the stack.
constexpr int kMaxJsonDepth = 64;

// Parses `text`. Throws InputError "<source> is not valid JSON: ..." for text that is not JSON,
// a number that overflows a double, a key repeated in one object (naming its JSON path) or
// nesting deeper than kMaxJsonDepth (naming the path where it happens).
Json parse_json(const std::string& text, const std::string& source, int max_depth = kMaxJsonDepth);

// The same for text that may also be meant as a plain string (a --set value): returns false and
// leaves `out` unchanged when `text` is not JSON at all; throws InputError as parse_json does
// when it is JSON that cannot be accepted (deeper than max_depth, a repeated key, an
// overflowing number).
bool parse_json_if_json(const std::string& text, const std::string& source, Json* out,
                        int max_depth = kMaxJsonDepth);

// The text of a JSON file named by a user (`what`: "scene file"). Throws InputError "cannot read
// the <what> '<path>': <why>" for a missing or unreadable file, anything but a regular file (a
// directory, or a device such as /dev/zero, which would be read forever) and a file larger than
// kMaxJsonFileBytes.
constexpr long kMaxJsonFileBytes = 64L << 20;
std::string read_json_file(const std::string& path, const std::string& what);

}  // namespace jelly::detail
