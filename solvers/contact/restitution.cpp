#include <jelly/solvers/contact/detail/restitution.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/measures.hpp>

namespace jelly {

Real affordable_scale(Real linear, Real quadratic, Real budget) {
  if (linear + quadratic <= budget) return 1;
  const Real disc = linear * linear + 4 * quadratic * budget;
  return disc > 0 && quadratic > 0
             ? std::clamp((-linear + std::sqrt(disc)) / (2 * quadratic), 0.0, 1.0)
             : 0.0;
}

Real add_bounded_bounces(const Model& model, const VecX& x0, const VecX& v0, Real t0, State& s1,
                         const std::vector<Bounce>& bounces, int threads) {
  if (bounces.empty()) return 1;
  Real quadratic = 0;
  bool one_frame = true;
  const Vec3 first = bounces.front().surface_velocity;
  for (const Bounce& b : bounces) {
    quadratic += 0.5 * model.mass[b.particle] * b.speed * b.speed;
    one_frame = one_frame && (b.surface_velocity - first).norm() <= 1e-12 * (1 + first.norm());
  }
  const Vec3 frame = one_frame ? first : Vec3::Zero();
  Real linear = 0;
  for (const Bounce& b : bounces)
    linear += model.mass[b.particle] * b.speed * (particle(s1.v, b.particle) - frame).dot(b.normal);
  const Real budget = energy_in_frame(model, x0, v0, frame, t0, threads) -
                      energy_in_frame(model, s1.x, s1.v, frame, s1.t, threads);
  const Real s = affordable_scale(linear, quadratic, budget);
  if (s <= 0) return 0;
  for (const Bounce& b : bounces) particle(s1.v, b.particle) += (s * b.speed) * b.normal;
  return s;
}

}  // namespace jelly
