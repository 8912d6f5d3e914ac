#pragma once
// The one check made before a file named by a user is opened for reading: a regular file, not a
// pipe, a device or a directory (which block a reader for ever or never end). Internal.
#include <string>

namespace jelly::detail {

// "" when `path` is an existing regular file (symbolic links followed); otherwise why not, as a
// clause for a message: "it is a pipe, not a file", "it is a directory", or the system's reason
// ("No such file or directory").
std::string why_not_a_regular_file(const std::string& path);

}  // namespace jelly::detail
