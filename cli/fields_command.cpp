#include <cstdio>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/field_reference.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

// The scene-key reference of the field tables: what docs' reference page and the Python stub
// check read.
int fields_command(const std::string& format) {
  const std::vector<FieldTableDoc> tables = scene_field_tables();
  if (format == "markdown") {
    std::fputs(field_tables_markdown(tables).c_str(), stdout);
  } else if (format == "json") {
    std::fputs(field_tables_json(tables).c_str(), stdout);
  } else {
    throw InputError("--format", "\"" + format + "\"", "\"markdown\" or \"json\"");
  }
  return kExitOk;
}

}  // namespace jelly::cli
