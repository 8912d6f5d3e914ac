#include <jelly/core/force.hpp>

namespace jelly {

const std::vector<EnumName<DefinitenessFix>>& definiteness_fixes() {
  static const std::vector<EnumName<DefinitenessFix>> table{
      {DefinitenessFix::kClampCompressed, "clamp",
       "ks (1 - l0/L) and kd c/L clamped to >= 0 (Choi & Ko 2002)"},
      {DefinitenessFix::kProjectPsd, "project", "each spring's block projected to PSD"},
      {DefinitenessFix::kNone, "none", "the exact symmetric Jacobian"},
  };
  return table;
}

std::string_view definiteness_name(DefinitenessFix fix) {
  return name_of(definiteness_fixes(), fix);
}

}  // namespace jelly
