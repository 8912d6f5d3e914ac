#include <jelly/solvers/contact/detail/position_contact.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/measures.hpp>
#include <jelly/solvers/contact/detail/friction.hpp>
#include <jelly/solvers/contact/detail/thickness.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>

namespace jelly {

namespace {

using friction::tangential;

// Slips shorter than this (m) have no direction of their own.
constexpr Real kTinySlip = 1e-12;

}  // namespace

bool PositionContact::begin(const Model& model, const Terrains& terrains, const State& s0, Real h,
                            bool keep_contacts) {
  const bool same_scene = model_ == &model && terrains_ == &terrains &&
                          slot_.size() == static_cast<size_t>(model.num_particles());
  model_ = &model;
  terrains_ = &terrains;
  coulomb_.clear();
  for (int k = 0; k < static_cast<int>(terrains.size()); ++k)
    if (terrain_contact_model(*terrains[k]).constrains_solves()) coulomb_.push_back(k);
  if (slot_.size() != static_cast<size_t>(model.num_particles()))
    slot_.assign(model.num_particles(), Slot{});
  if (keep_contacts && same_scene && !coulomb_.empty()) {
    for (int i : active_) {
      Slot& s = slot_[i];
      s.normal_correction = 0;
      s.friction_used = 0;
      if (s.mode == Mode::kNew) s.mode = Mode::kStick;
    }
  } else {
    for (int i : active_) slot_[i] = Slot{};
    active_.clear();
  }
  frozen_ = false;
  if (coulomb_.empty()) return false;
  thickness::fill(model, gap_);
  t1_ = s0.t + h;
  h_ = h;
  x0_ = s0.x;
  v0_ = s0.v;
  return true;
}

int PositionContact::deepest(const Vec3& p, Real gap, Real* distance) const {
  int best = -1;
  Real d_best = 0;
  for (int k : coulomb_) {
    const Terrain& terrain = *(*terrains_)[k];
    const Real d = terrain.signed_distance(p, t1_) - gap;
    if (d < d_best && terrain.can_contact(p, t1_)) {
      d_best = d;
      best = k;
    }
  }
  *distance = d_best;
  return best;
}

void PositionContact::activate(int i, int terrain, const Vec3& p) {
  Slot& s = slot_[i];
  const Terrain& t = *(*terrains_)[terrain];
  s.mode = Mode::kNew;
  s.terrain = terrain;
  s.normal = t.normal(p, t1_);
  s.surface_velocity = t.surface_velocity(p, t1_);
  s.slip_direction.setZero();
  s.normal_correction = 0;
  s.friction_used = 0;
}

Vec3 PositionContact::anchor(int i) const {
  const Slot& s = slot_[i];
  const Vec3 a = particle(x0_, i) + h_ * s.surface_velocity;
  return a - ((*terrains_)[s.terrain]->signed_distance(a, t1_) - gap_[i]) * s.normal;
}

void PositionContact::constrain_residual(const VecX& x, VecX& r) {
  for (int i : active_) {
    Slot& s = slot_[i];
    if (s.mode == Mode::kFree) continue;
    auto ri = particle(r, i);
    const Real rn = ri.dot(s.normal);
    if (rn >= 0 && !frozen_) {  // the residual pulls it off the surface: the solve lifts it
      s.mode = Mode::kFree;
      continue;
    }
    const Real pressure = std::max(-rn, 0.0);  // the contact force the surface exerts
    const Vec3 rt = tangential(ri, s.normal);
    const ContactParams& c = (*terrains_)[s.terrain]->contact();
    if (s.mode == Mode::kNew) s.mode = Mode::kStick;  // held at its anchor first
    if (s.mode == Mode::kStick) {
      const Real holding = rt.norm();
      if (holding <= c.static_friction * pressure || frozen_) {
        ri.setZero();
        continue;
      }
      s.mode = Mode::kSlide;
      s.slip_direction = rt / holding;
    } else if (!frozen_) {
      // Sliding: it sticks when the force that would hold it at its anchor for the whole step,
      // r_t + m (x - anchor)_t / h^2 (its inertia; the springs' change is neglected), lies in
      // the static cone; else the friction opposes its slip.
      const Vec3 slip = tangential(Vec3(particle(x, i)) - anchor(i), s.normal);
      const Vec3 holding = rt + (model_->mass[i] / (h_ * h_)) * slip;
      if (holding.norm() <= c.static_friction * pressure) {
        s.mode = Mode::kStick;
        ri.setZero();
        continue;
      }
      const Real length = slip.norm();
      if (length > kTinySlip) s.slip_direction = slip / length;
    }
    // Kinetic friction against the sliding; frozen, the last one (a friction force that follows
    // the iterate's normal force makes stiff contacts oscillate).
    if (!frozen_) s.friction = -(c.friction * pressure) * s.slip_direction;
    ri = rt + s.friction;
  }
}

void PositionContact::project(VecX& x) {
  const int n = model_->num_particles();
  active_.clear();
  for (int i = 0; i < n; ++i) {
    Slot& s = slot_[i];
    auto xi = particle(x, i);
    if (s.mode == Mode::kFree) {
      Real d;
      const int k = deepest(xi, gap_[i], &d);
      if (k < 0) continue;
      activate(i, k, xi);
    } else if (s.mode == Mode::kSlide && !frozen_) {
      // The friction overshot (the particle would stop within the step): it sticks.
      const Vec3 slip = tangential(Vec3(xi) - anchor(i), s.normal);
      if (slip.dot(s.slip_direction) <= 0) s.mode = Mode::kStick;
    }
    active_.push_back(i);
    const Terrain& terrain = *(*terrains_)[s.terrain];
    s.normal = terrain.normal(xi, t1_);
    s.surface_velocity = terrain.surface_velocity(xi, t1_);
    if (s.mode == Mode::kStick) {
      xi = anchor(i);
    } else {
      xi -= (terrain.signed_distance(xi, t1_) - gap_[i]) * s.normal;
    }
  }
}

void PositionContact::project_with_friction(VecX& x) {
  const int n = model_->num_particles();
  for (int i = 0; i < n; ++i) {
    auto xi = particle(x, i);
    Real d;
    const int k = deepest(xi, gap_[i], &d);
    if (k < 0) continue;
    Slot& s = slot_[i];
    if (s.mode == Mode::kFree) {
      activate(i, k, xi);
      active_.push_back(i);
    }
    xi -= d * s.normal;
    s.normal_correction -= d;
    // Position-based Coulomb friction on the displacement relative to the surface since the
    // start of the substep, within a budget of mu times the normal corrections so far (this is
    // called several times per substep; friction applied at each call would add up).
    const Vec3 slip = tangential(Vec3(xi) - particle(x0_, i) - h_ * s.surface_velocity, s.normal);
    const Real length = slip.norm();
    if (length == 0) continue;
    const ContactParams& c = (*terrains_)[k]->contact();
    if (s.mode != Mode::kSlide && length <= c.static_friction * s.normal_correction) {
      xi -= slip;
      s.mode = Mode::kStick;
      continue;
    }
    s.mode = Mode::kSlide;
    const Real budget = c.friction * s.normal_correction - s.friction_used;
    if (budget <= 0) continue;
    const Real take = std::min(budget, length);
    xi -= (take / length) * slip;
    s.friction_used += take;
  }
}

void PositionContact::finish(const Model& model, State& s1, int threads) {
  bounces_.clear();
  for (int i : active_) {
    const Slot& s = slot_[i];
    if (s.mode == Mode::kFree) continue;
    auto v = particle(s1.v, i);
    const Real vn = (v - s.surface_velocity).dot(s.normal);
    if (vn < 0) v -= vn * s.normal;
    const ContactParams& c = (*terrains_)[s.terrain]->contact();
    const Real approach = -(Vec3(particle(v0_, i)) - s.surface_velocity).dot(s.normal);
    if (approach > c.resting_speed && c.restitution > 0)
      bounces_.push_back({i, s.normal, s.surface_velocity, c.restitution * approach});
  }
  if (bounces_.empty()) return;
  if (add_bounded_bounces(model, x0_, v0_, t1_ - h_, s1, bounces_, threads) < 1)
    ++counters_.restitution_limited;
}

}  // namespace jelly
