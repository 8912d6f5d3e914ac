#pragma once
// What implicit_euler's next steps depend on besides the state, with named fields, and its
// form as the numbers a checkpoint stores (Integrator::internal_state()):
//   [size of warm_start (0: none), warm_start...,
//    (only with body pairs: -(1 + size of body_pairs), body_pairs...), contact_set...]
// A negative count marks the body pairs, so files written before they existed read the same.
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

struct ImplicitEulerCheckpoint {
  VecX warm_start;                // the last step's dv, CG's first guess (empty: none)
  std::vector<Real> body_pairs;   // ImplicitBodyContact::save()'s values (empty: none)
  std::vector<Real> contact_set;  // ImplicitContact::save()'s values

  std::vector<Real> to_numbers() const;
  // Throws InputError for numbers to_numbers() cannot have written.
  static ImplicitEulerCheckpoint from_numbers(const std::vector<Real>& data);
};

}  // namespace jelly
