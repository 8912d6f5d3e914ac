#include <jelly/core/detail/input_file.hpp>

#include <cerrno>
#include <cstring>

#include <sys/stat.h>

namespace jelly::detail {

std::string why_not_a_regular_file(const std::string& path) {
  struct stat info {};
  if (stat(path.c_str(), &info) != 0) return std::strerror(errno);
  if (S_ISREG(info.st_mode)) return "";
  if (S_ISDIR(info.st_mode)) return "it is a directory";
  return std::string("it is ") +
         (S_ISCHR(info.st_mode)    ? "a character device"
          : S_ISBLK(info.st_mode)  ? "a block device"
          : S_ISFIFO(info.st_mode) ? "a pipe"
          : S_ISSOCK(info.st_mode) ? "a socket"
                                   : "not a regular file") +
         ", not a file";
}

}  // namespace jelly::detail
