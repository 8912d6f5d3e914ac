#include <cstdio>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "output.hpp"

namespace jelly::cli {

int info_command(const std::string& path) {
  const std::string text = describe_file(path);
  std::fputs(text.c_str(), stdout);
  if (!text.empty() && text.back() != '\n') std::fputc('\n', stdout);
  return kExitOk;
}

}  // namespace jelly::cli
