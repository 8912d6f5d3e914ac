#pragma once
// How the geometric (transverse) stiffness of a spring is kept from making -K indefinite
// (docs/implicit.md): an option of the implicit integrators.
#include <string_view>
#include <vector>

#include <jelly/core/enum_names.hpp>

namespace jelly {

// Per spring, the symmetric part of -df_a/dxa is ks u u^T + s P, with P = I - u u^T,
// s = ks (1 - l0/L) + kd c / L (c = (va - vb).u); it is negative for a compressed (or a closing)
// spring.
enum class DefinitenessFix {
  kClampCompressed,  // Choi & Ko 2002: ks (1 - l0/L) and kd c/L each clamped to >= 0 (default)
  kProjectPsd,       // the spring's 3x3 block projected to PSD: s clamped to >= 0
  kNone,             // the exact symmetric Jacobian; M - h D - h^2 K may be indefinite
};
// "clamp", "project", "none".
const std::vector<EnumName<DefinitenessFix>>& definiteness_fixes();
std::string_view definiteness_name(DefinitenessFix fix);

}  // namespace jelly
