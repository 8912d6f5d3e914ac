#pragma once
// Internal and external forces of the mass-spring model (the report's formulas).
#include <jelly/core/model.hpp>

namespace jelly {

// A spring shorter than this fraction of its rest length is degenerate: its direction is taken
// from the rest positions (forces and Jacobians alike).
inline constexpr Real kDegenerateLength = 1e-9;

// f = m g + sum over springs of the spring and damper forces. f must have size 3N.
// For a spring (a, b), with d = (xa - xb) / |xa - xb|:
//   spring force on a  = -ks (|xa - xb| - l0) d
//   damper force on a  = -kd ((va - vb) . d) d
// and b receives the opposite. No allocation, no branch on the spring type.
void compute_forces(const Model& model, const VecX& x, const VecX& v, VecX& f);

// Adds only the spring and damper forces to f.
void add_spring_forces(const Model& model, const VecX& x, const VecX& v, VecX& f);

// f = M^-1 f in place (each entry times 1 / m of its particle), on up to `threads` threads: the
// one definition of the accelerations' division (the same bits for any thread count).
void divide_by_masses(const Model& model, VecX& f, int threads = 1);

}  // namespace jelly
