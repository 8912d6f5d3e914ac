#include <jelly/solvers/contact/detail/implicit_body_contact.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/contact/detail/friction.hpp>
#include <jelly/solvers/contact/detail/restitution.hpp>

namespace jelly {

namespace {

using friction::kStickViscosity;
using friction::tangential;

using Mat3 = Eigen::Matrix3d;
using Clock = std::chrono::steady_clock;

// A carried pair whose explicit prediction ends at most this far apart stays active.
constexpr Real kPairTouchTolerance = 1e-6;  // m
// A candidate whose end gap a solve makes smaller than -this fraction of r_i + r_j becomes
// active and the step solves again; a shallower overlap is left to the next step (whose
// prediction makes the pair active), which saves most of those solves.
constexpr Real kPairPenetrationFraction = 1e-3;
// The largest overlap, as a fraction of r_i + r_j, a step may end with: deeper ones (the pair
// spring's compliance under a whole body's momentum at a landing) are projected out after the
// solve. Resting loads compress a pair far less.
constexpr Real kLargestOverlap = 5e-3;
constexpr int kProjectionPasses = 4;
// Candidates: each radius grown by this fraction besides the distance travelled in the step, so
// that the matrix pattern (the union of the candidates) rarely needs a new pair.
constexpr Real kCandidateMargin = 0.25;

// Adds `block` to the 3x3 block (row particle r, column particle c) of a full-storage matrix of
// dense 3x3 blocks with sorted rows.
void add_block(SparseMatrix& a, int r, int c, const Mat3& block) {
  const int* outer = a.outerIndexPtr();
  const int start = outer[3 * c], stride = outer[3 * c + 1] - outer[3 * c];
  const int* rows = a.innerIndexPtr() + start;
  const int* at = std::lower_bound(rows, rows + stride, 3 * r);
  if (at == rows + stride || *at != 3 * r)
    throw std::logic_error("implicit body contact: the matrix pattern lacks a contact block");
  Real* values = a.valuePtr() + start + (at - rows);
  for (int q = 0; q < 3; ++q)
    for (int k = 0; k < 3; ++k) values[q * stride + k] += block(k, q);
}

}  // namespace

bool ImplicitBodyContact::begin_step(const Model& model, BodyContact& contact, const State& s0,
                                     const VecX& f, Real h) {
  const int np = model.num_particles();
  h_ = h;
  model_ = &model;
  params_ = contact.params();
  x0_ = s0.x;
  v0_ = s0.v;
  pad_.resize(np);
  for (int i = 0; i < np; ++i) {
    const Vec3 v1 = particle(v0_, i) + (h / model.mass[i]) * particle(f, i);
    pad_[i] = h * std::max(particle(v0_, i).norm(), v1.norm());
  }
  const std::vector<BroadPhase::Pair>& candidates =
      contact.find_candidates(model, x0_, pad_, kCandidateMargin);
  const auto start = Clock::now();
  pairs_.clear();
  active_ = 0;
  const Real mu = params_.friction, mu_s = params_.static_friction;
  for (const auto& [i, j] : candidates) {
    const Vec3 d = particle(x0_, j) - particle(x0_, i);
    const Real dist = d.norm();
    if (!(dist > 0)) continue;  // coincident: no direction to push along
    const Real wi = contact.inverse_mass(i), wj = contact.inverse_mass(j);
    Pair p;
    p.i = i;
    p.j = j;
    p.normal = d / dist;
    p.reach = contact.radius(i) + contact.radius(j);
    p.gap0 = dist - p.reach;
    p.mass = 1 / (wi + wj);
    p.approach = -(particle(v0_, j) - particle(v0_, i)).dot(p.normal);
    // The explicit prediction of the relative velocity.
    const Vec3 w1 = particle(v0_, j) + (h / model.mass[j]) * particle(f, j) - particle(v0_, i) -
                    (h / model.mass[i]) * particle(f, i);
    const Real predicted_gap = p.gap0 + h * p.normal.dot(w1);
    const auto old = std::lower_bound(carried_.begin(), carried_.end(), std::make_pair(i, j),
                                      [](const Carried& c, const std::pair<int, int>& k) {
                                        return std::make_pair(c.i, c.j) < k;
                                      });
    const bool was_active = old != carried_.end() && old->i == i && old->j == j;
    p.kappa = kStiffness;
    if (was_active && predicted_gap <= kPairTouchTolerance) {
      p.active = true;
      p.mode = old->mode;
      p.viscosity = old->viscosity;
      p.kappa = old->kappa;
    } else if (predicted_gap < 0) {
      p.active = true;
      // Stick or slide as a lone pair would: the normal velocity change the contact needs
      // bounds the friction.
      const Real dvn = std::max(-predicted_gap / h, 0.0);
      const Real speed = tangential(w1, p.normal).norm();
      if (mu_s <= 0 || speed > mu_s * dvn) {
        p.mode = Mode::kSlide;
        p.viscosity = speed > mu * dvn ? mu * p.mass * dvn / (speed - mu * dvn) : 0.0;
      }
    }
    if (p.active) ++active_;
    pairs_.push_back(p);
  }
  seconds_ = std::chrono::duration<double>(Clock::now() - start).count();
  // Without a candidate no finish() follows: the pairs carried from an earlier contact are over
  // (they must not count as active when the bodies meet again).
  if (pairs_.empty()) carried_.clear();
  return !pairs_.empty();
}

Mat3 ImplicitBodyContact::block(const Pair& p) const {
  const Mat3 nn = p.normal * p.normal.transpose();
  const Real c = p.mode == Mode::kStick ? stick_viscosity(p) : p.viscosity;
  return (p.kappa * p.mass) * nn + c * (Mat3::Identity() - nn);
}

Vec3 ImplicitBodyContact::impulse(const Pair& p, const Vec3& w1) const {
  const Real c = p.mode == Mode::kStick ? stick_viscosity(p) : p.viscosity;
  const Real gap1 = p.gap0 + h_ * p.normal.dot(w1);
  return (-(p.kappa * p.mass / h_) * gap1) * p.normal - c * tangential(w1, p.normal);
}

void ImplicitBodyContact::add_terms(SparseMatrix& a, VecX* b) const {
  for (const Pair& p : pairs_) {
    if (!p.active) continue;
    const Mat3 hb = block(p);
    add_block(a, p.i, p.i, hb);
    add_block(a, p.j, p.j, hb);
    add_block(a, p.i, p.j, -hb);
    add_block(a, p.j, p.i, -hb);
    if (b != nullptr) {
      const Vec3 q = impulse(p, particle(v0_, p.j) - particle(v0_, p.i));
      particle(*b, p.j) += q;
      particle(*b, p.i) -= q;
    }
  }
}

void ImplicitBodyContact::subtract_impulses(const VecX& v1, VecX& w) const {
  for (const Pair& p : pairs_) {
    if (!p.active) continue;
    const Vec3 q = impulse(p, particle(v1, p.j) - particle(v1, p.i));
    particle(w, p.j) -= q;
    particle(w, p.i) += q;
  }
}

bool ImplicitBodyContact::update(const VecX& dv, bool commit) {
  const auto start = Clock::now();
  bool changed = false;
  const Real mu = params_.friction, mu_s = params_.static_friction;
  for (Pair& p : pairs_) {
    const Vec3 w1 = particle(v0_, p.j) + particle(dv, p.j) - particle(v0_, p.i) - particle(dv, p.i);
    if (!p.active) {
      const Real gap1 = p.gap0 + h_ * p.normal.dot(w1);
      if (gap1 >= -kPairPenetrationFraction * p.reach) continue;
      changed = true;
      if (!commit) continue;
      p.active = true;
      const Real dvn = -gap1 / h_;
      const Real speed = tangential(w1, p.normal).norm();
      p.mode = Mode::kStick;
      p.viscosity = 0;
      if (mu_s <= 0 || speed > mu_s * dvn) {
        p.mode = Mode::kSlide;
        p.viscosity = speed > mu * dvn ? mu * p.mass * dvn / (speed - mu * dvn) : 0.0;
      }
      continue;
    }
    const Vec3 q = impulse(p, w1);
    const Real pn = q.dot(p.normal);
    p.release = false;
    if (pn < 0) {  // the spring would pull: let go
      // A pair that touched at the start of the step (gap0 <= 0) is pulled only by the little
      // its spring is stretched at the end: it is held for this step and let go at the next,
      // without another solve. Otherwise solve again without it.
      if (p.gap0 <= 0) {
        p.release = true;
      } else {
        changed = true;
        if (commit) p.active = false;
      }
      continue;
    }
    // Friction, for the next solve or step (a change of it alone is no reason to solve again).
    if (p.mode == Mode::kStick) {
      const Real pt = tangential(q, p.normal).norm();
      if (pt > mu_s * pn) {  // outside the cone: slide
        p.mode = Mode::kSlide;
        const Real force = mu * pn;
        p.viscosity = pt > force ? force * p.mass / (pt - force) : 0.0;
      }
    } else if (mu > 0) {
      const Real speed = tangential(w1, p.normal).norm();
      const Real viscosity = mu * pn / std::max(speed, 1e-300);
      if (mu_s > 0 && viscosity >= kStickViscosity * p.mass) {
        p.mode = Mode::kStick;
        p.viscosity = 0;
      } else {
        p.viscosity = viscosity;
      }
    }
  }
  if (changed && commit) {
    active_ = static_cast<int>(
        std::count_if(pairs_.begin(), pairs_.end(), [](const Pair& p) { return p.active; }));
    ++counters_.extra_solves;
  } else if (changed) {
    ++counters_.not_converged;  // the last solve's set stays
  }
  seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
  return changed;
}

void ImplicitBodyContact::finish(const Model& model, State& s1, BodyContact& contact, int threads) {
  const auto start = Clock::now();
  resolved_.clear();
  carried_.clear();
  for (const Pair& p : pairs_) {
    if (!p.active || p.release) continue;
    resolved_.emplace_back(p.i, p.j);
    carried_.push_back({p.i, p.j, p.mode, p.viscosity, p.kappa});
  }
  std::sort(carried_.begin(), carried_.end(), [](const Carried& a, const Carried& b) {
    return std::make_pair(a.i, a.j) < std::make_pair(b.i, b.j);
  });
  // Safety net: overlaps deeper than kLargestOverlap are projected back to it along the line of
  // centres, weighted by inverse mass; the lever the projection adds would change the angular
  // momentum by a n x (v_j - v_i), which a tangential impulse takes back exactly (as in
  // BodyContact::resolve).
  for (int pass = 0; pass < kProjectionPasses; ++pass) {
    bool any_projected = false;
    for (const Pair& p : pairs_) {
      auto xi = particle(s1.x, p.i);
      auto xj = particle(s1.x, p.j);
      const Vec3 d = xj - xi;
      const Real dist = d.norm();
      const Real overlap = (1 - kLargestOverlap) * p.reach - dist;
      if (overlap <= 0 || !(dist > 0)) continue;
      any_projected = true;
      ++counters_.projected;
      const Vec3 n = d / dist;
      const Real wi = contact.inverse_mass(p.i), wj = contact.inverse_mass(p.j);
      const Real a = overlap / (wi + wj);
      xi -= (a * wi) * n;
      xj += (a * wj) * n;
      auto vi = particle(s1.v, p.i);
      auto vj = particle(s1.v, p.j);
      const Vec3 rel = vj - vi;
      const Vec3 q = (-a / (dist + overlap)) * tangential(rel, n);
      vi -= wi * q;
      vj += wj * q;
    }
    if (!any_projected) break;
  }
  // Restitution: e times the approach at the start of the step, along the end-of-step line of
  // centres, for the active pairs that approached faster than the resting speed.
  const Real e = params_.restitution;
  bool any = false;
  if (e > 0) {
    for (const Pair& p : pairs_) {
      if (!p.active || !(p.approach > params_.resting_speed)) continue;
      const Vec3 d = particle(s1.x, p.j) - particle(s1.x, p.i);
      const Real dist = d.norm();
      if (!(dist > 0)) continue;
      if (!any) bounce_.setZero(s1.v.size());
      any = true;
      const Vec3 impulse = (p.mass * e * p.approach / dist) * d;
      particle(bounce_, p.j) += contact.inverse_mass(p.j) * impulse;
      particle(bounce_, p.i) -= contact.inverse_mass(p.i) * impulse;
    }
  }
  if (any) {
    // Largest s in [0, 1] whose kinetic energy gain s linear + s^2 quadratic fits in the energy
    // the step lost.
    Real linear = 0, quadratic = 0;
    for (int k = 0; k < model.num_particles(); ++k) {
      const Vec3 dv = particle(bounce_, k);
      linear += model.mass[k] * particle(s1.v, k).dot(dv);
      quadratic += 0.5 * model.mass[k] * dv.squaredNorm();
    }
    const Real budget = energy_in_frame(model, x0_, v0_, Vec3::Zero(), 0, threads) -
                        energy_in_frame(model, s1.x, s1.v, Vec3::Zero(), 0, threads);
    const Real s = affordable_scale(linear, quadratic, budget);
    if (linear + quadratic > budget) ++counters_.restitution_limited;
    if (s > 0) s1.v += s * bounce_;
  }
  seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
  contact.record_step(resolved_, seconds_);
}

size_t ImplicitBodyContact::saved_size() const { return kSavedPerPair * carried_.size(); }

void ImplicitBodyContact::save(std::vector<Real>& out) const {
  for (const Carried& c : carried_) {
    out.push_back(c.i);
    out.push_back(c.j);
    out.push_back(c.mode == Mode::kSlide ? 1 : 0);
    out.push_back(c.viscosity);
    out.push_back(c.kappa);
  }
}

void ImplicitBodyContact::restore(const Real* data, size_t size) {
  require(size % kSavedPerPair == 0, "integrator state (body contact pairs)", size,
          "5 numbers per pair");
  carried_.clear();
  constexpr Real kMaxIndex = std::numeric_limits<int>::max();
  for (size_t k = 0; k < size; k += kSavedPerPair) {
    const Real i = data[k], j = data[k + 1], mode = data[k + 2], viscosity = data[k + 3],
               kappa = data[k + 4];
    require(i >= 0 && i == std::floor(i) && j > i && j == std::floor(j) && j <= kMaxIndex,
            "integrator state (body contact pair)", i, "two particle indices 0 <= i < j");
    require(mode == 0 || mode == 1, "integrator state (body contact pair mode)", mode,
            "0 (stick) or 1 (slide)");
    require(std::isfinite(viscosity) && viscosity >= 0,
            "integrator state (body contact pair viscosity)", viscosity, "a finite value >= 0");
    require(std::isfinite(kappa) && kappa > 0, "integrator state (body contact pair stiffness)",
            kappa, "a finite value > 0");
    carried_.push_back({static_cast<int>(i), static_cast<int>(j),
                        mode != 0 ? Mode::kSlide : Mode::kStick, viscosity, kappa});
  }
  std::sort(carried_.begin(), carried_.end(), [](const Carried& a, const Carried& b) {
    return std::make_pair(a.i, a.j) < std::make_pair(b.i, b.j);
  });
}

}  // namespace jelly
