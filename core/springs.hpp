#pragma once
// Springs with dampers between particle pairs, stored once each as parallel arrays
// (struct-of-arrays) for the force loop, with their type and coefficients.
#include <cstdint>
#include <string_view>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

enum class SpringType : std::uint8_t { kStructural = 0, kShear = 1, kBending = 2 };
inline constexpr int kSpringTypeCount = 3;
std::string_view spring_type_name(SpringType type);

// Stiffness ks (N/m) and damping kd (N s/m) of one spring type.
struct SpringCoefficients {
  Real ks = 1400;
  Real kd = 50;
};

// Springs stored once each, as parallel arrays (struct-of-arrays) for the force loop.
struct Springs {
  std::vector<int> a, b;
  std::vector<Real> rest_length, ks, kd;
  std::vector<SpringType> type;

  int size() const { return static_cast<int>(a.size()); }
  void add(int a_index, int b_index, Real rest, SpringCoefficients c, SpringType t);
  int count(SpringType t) const;
  // Sets ks and kd of every spring of type t.
  void set_coefficients(SpringType t, SpringCoefficients c);
  // Appends `other` with its particle indices offset by `shift`.
  void append(const Springs& other, int shift);
};

}  // namespace jelly
