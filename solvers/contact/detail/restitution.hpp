#pragma once
// Restitution within an energy budget, shared by the contacts that resolve impacts after a
// (sub)step (implicit_euler's terrain and body contact, projective_dynamics' and xpbd's
// position contact): bounces are scaled down so that the step does not end with more energy
// than it started with.
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>

namespace jelly {

// A restitution impulse after a (sub)step.
struct Bounce {
  int particle;
  Vec3 normal;
  Vec3 surface_velocity;
  Real speed;  // e times the approach speed
};

// The largest s in [0, 1] whose kinetic energy gain s linear + s^2 quadratic fits in `budget`
// (1 when the whole gain fits).
Real affordable_scale(Real linear, Real quadratic, Real budget);

// Adds speed * normal to the velocity of each bounce, all scaled by the largest s in [0, 1] that
// keeps the total energy of s1 (in the frame of the surfaces when they move alike, else the
// fixed frame) at most that of the start (x0, v0 at time t0); the energies on up to `threads`
// threads. Returns s.
Real add_bounded_bounces(const Model& model, const VecX& x0, const VecX& v0, Real t0, State& s1,
                         const std::vector<Bounce>& bounces, int threads);

}  // namespace jelly
