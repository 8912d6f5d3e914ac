#pragma once
// The mass-spring model: particle masses, springs with dampers (struct-of-arrays) and gravity.
#include <array>
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
};

struct Model {
  VecX mass;           // [N] particle masses (kg)
  VecX rest_position;  // [3N] the positions the rest lengths were measured in
  Springs springs;
  Vec3 gravity{0, -9.8, 0};

  int num_particles() const { return static_cast<int>(mass.size()); }
  int num_dofs() const { return 3 * num_particles(); }
  // Throws InputError when a mass, index, rest length or coefficient is out of range.
  void validate() const;
};

}  // namespace jelly
