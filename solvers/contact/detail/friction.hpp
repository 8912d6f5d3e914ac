#pragma once
// What the contacts' friction models share (implicit_euler's terrain and body contact,
// projective_dynamics' and xpbd's position contact).
#include <jelly/core/types.hpp>

namespace jelly::friction {

// The part of w in the plane normal to the unit vector n.
inline Vec3 tangential(const Vec3& w, const Vec3& n) { return w - w.dot(n) * n; }

// A sliding contact whose friction viscosity reaches this many times its (reduced) mass has all
// but stopped (its tangential speed is under 1 % of the free one): it sticks.
constexpr Real kStickViscosity = 100;

}  // namespace jelly::friction
