#include <jelly/core/definiteness.hpp>

namespace jelly {

std::string_view definiteness_name(DefinitenessFix fix) {
  switch (fix) {
    case DefinitenessFix::kClampCompressed:
      return "clamp";
    case DefinitenessFix::kProjectPsd:
      return "project";
    case DefinitenessFix::kNone:
      return "none";
  }
  return "?";
}

bool parse_definiteness(std::string_view text, DefinitenessFix* fix) {
  for (DefinitenessFix f :
       {DefinitenessFix::kClampCompressed, DefinitenessFix::kProjectPsd, DefinitenessFix::kNone}) {
    if (text == definiteness_name(f)) {
      *fix = f;
      return true;
    }
  }
  return false;
}

}  // namespace jelly
