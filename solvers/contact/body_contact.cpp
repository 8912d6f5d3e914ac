#include <jelly/solvers/contact/detail/body_contact.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Eigenvalues>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/contact/detail/body_contact_fields.hpp>

namespace jelly {

namespace {

void check_body_friction(const BodyContactParams& p, const std::string& prefix) {
  require(p.static_friction >= p.friction, prefix + "static_friction", p.static_friction,
          "a finite number >= friction (" + to_text(p.friction) + ")");
}

// static_friction not given: at least friction.
void body_static_friction_default(JsonFields& f, BodyContactParams& p) {
  if (!json_field_has(f, "static_friction"))
    p.static_friction = std::max(p.static_friction, p.friction);
}

}  // namespace

const FieldTable<BodyContactParams>& body_contact_fields() {
  using P = BodyContactParams;
  static const FieldTable<P> table{
      "BodyContactParams",
      "body_contact",
      "Contact between bodies (docs/contact.md); each body's particles are spheres of its "
      "radius",
      {
          boolean_field<&P::enabled>("enabled", "Contact between different bodies"),
          boolean_field<&P::self_contact>("self_contact",
                                          "Contact between parts of one body that no spring joins"),
          number_field<&P::restitution>("restitution", "", range_closed(0, 1), "a number in [0, 1]",
                                        "Normal velocity kept, reversed, by a bounce"),
          number_field<&P::friction>("friction", "", range_at_least(0), "a finite number >= 0",
                                     "Kinetic friction coefficient"),
          number_field<&P::static_friction>(
              "static_friction", "", range_finite(), "a finite number >= friction",
              "Static friction coefficient, >= friction (default: at least friction)"),
          number_field<&P::resting_speed>("resting_speed", "m/s", range_at_least(0),
                                          "a finite speed >= 0",
                                          "A slower approach is absorbed, never reflected"),
          integer_field<&P::iterations>("iterations", "", range_closed(1, 100),
                                        "an integer in [1, 100]",
                                        "Passes over the contact pairs per step"),
      },
      &check_body_friction,
      &body_static_friction_default,
  };
  return table;
}

void BodyContactParams::validate(const std::string& prefix) const {
  validate_fields(body_contact_fields(), *this, prefix);
}

BodyContactParams BodyContactParams::read(JsonFields& f) {
  BodyContactParams p;
  read_fields(body_contact_fields(), f, p, f.prefix(), /*reject_unknown=*/true);
  return p;
}

Json BodyContactParams::to_json() const {
  Json j = Json::object();
  write_fields(body_contact_fields(), *this, j);
  return j;
}

BodyContact::BodyContact(BodyContactParams params) : params_(params) {
  params_.validate("body_contact.");
}

bool BodyContact::active(const Model& model) const {
  return (params_.enabled && model.num_bodies() >= 2) ||
         (params_.self_contact && model.num_bodies() >= 1);
}

void BodyContact::prepare(const Model& model) {
  const int n = model.num_particles();
  // The inverse masses every time (Simulator::set_particle_mass changes them between steps; as
  // cheap as the broad phase's pass over the particles, and no allocation once sized).
  inverse_mass_.resize(n);
  inverse_mass_ = model.mass.cwiseInverse();
  for (int k = 0; k < model.pins.size(); ++k) inverse_mass_[model.pins.particles[k]] = 0;
  if (prepared_for_ == &model && prepared_particles_ == n &&
      prepared_springs_ == model.springs.size())
    return;
  prepared_for_ = &model;
  prepared_particles_ = n;
  prepared_springs_ = model.springs.size();
  radius_.resize(n);
  body_.assign(n, -1);
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Body& body = model.bodies[b];
    const Real r = body.radius > 0 ? body.radius : 0.5 * body.spacing;
    for (int i = body.first_particle; i < body.end_particle(); ++i) {
      body_[i] = b;
      radius_[i] = r;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (!(radius_[i] > 0)) radius_[i] = 0;  // a particle outside every body takes no part
  }
  // The springs' neighbours of each particle (CSR, sorted).
  neighbour_start_.assign(n + 1, 0);
  const Springs& s = model.springs;
  for (int k = 0; k < s.size(); ++k) {
    ++neighbour_start_[s.a[k] + 1];
    ++neighbour_start_[s.b[k] + 1];
  }
  for (int i = 0; i < n; ++i) neighbour_start_[i + 1] += neighbour_start_[i];
  neighbours_.resize(neighbour_start_[n]);
  std::vector<int> fill(neighbour_start_.begin(), neighbour_start_.end() - 1);
  for (int k = 0; k < s.size(); ++k) {
    neighbours_[fill[s.a[k]]++] = s.b[k];
    neighbours_[fill[s.b[k]]++] = s.a[k];
  }
  for (int i = 0; i < n; ++i)
    std::sort(neighbours_.begin() + neighbour_start_[i],
              neighbours_.begin() + neighbour_start_[i + 1]);
}

bool BodyContact::joined(int i, int j) const {
  const auto begin = neighbours_.begin() + neighbour_start_[i];
  const auto end = neighbours_.begin() + neighbour_start_[i + 1];
  return std::binary_search(begin, end, j);
}

void BodyContact::filter(const Model& /*model*/) {
  contacts_.clear();
  for (const BroadPhase::Pair& p : candidates_) {
    const int bi = body_[p.first], bj = body_[p.second];
    if (bi < 0 || bj < 0 || radius_[p.first] <= 0 || radius_[p.second] <= 0) continue;
    if (bi != bj ? !params_.enabled : (!params_.self_contact || joined(p.first, p.second)))
      continue;
    if (inverse_mass_[p.first] + inverse_mass_[p.second] <= 0) continue;  // two pins
    contacts_.push_back(p);
  }
}

void BodyContact::check_no_overlap(const Model& model, const VecX& x, Real tolerance) {
  if (!active(model)) return;
  prepare(model);
  broad_.find_pairs(x, radius_, candidates_);
  filter(model);
  for (const BroadPhase::Pair& p : contacts_) {
    const Real reach = radius_[p.first] + radius_[p.second];
    const Real distance = (particle(x, p.second) - particle(x, p.first)).norm();
    if (distance >= reach * (1 - tolerance)) continue;
    const Body& a = model.bodies[body_[p.first]];
    const Body& b = model.bodies[body_[p.second]];
    const std::string what =
        "particle " + std::to_string(p.first - a.first_particle) + " of body \"" + a.name +
        "\" and particle " + std::to_string(p.second - b.first_particle) + " of body \"" + b.name +
        "\" are " + to_text(distance) + " m apart, closer than their contact radii " +
        to_text(radius_[p.first]) + " + " + to_text(radius_[p.second]) + " m";
    if (body_[p.first] != body_[p.second]) {
      throw InputError("bodies \"" + a.name + "\" and \"" + b.name + "\" overlap at the start: " +
                       what + "; move them apart (or make their radius smaller)");
    }
    throw InputError("body \"" + a.name + "\" touches itself at the start (self_contact): " + what +
                     "; turn body_contact.self_contact off or make its radius smaller");
  }
}

const std::vector<BroadPhase::Pair>& BodyContact::find_candidates(const Model& model, const VecX& x,
                                                                  const VecX& pad, Real margin) {
  const auto t0 = std::chrono::steady_clock::now();
  prepare(model);
  padded_ = (1 + margin) * radius_ + pad;
  for (int i = 0; i < padded_.size(); ++i) {
    if (!(radius_[i] > 0)) padded_[i] = 0;
  }
  broad_.find_pairs(x, padded_, candidates_);
  filter(model);
  stats_.broad_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return contacts_;
}

void BodyContact::record_step(const std::vector<BroadPhase::Pair>& pairs, double narrow_seconds) {
  contacts_ = pairs;
  stats_.pairs += static_cast<long>(pairs.size());
  stats_.narrow_seconds += narrow_seconds;
  ++stats_.steps;
}

bool BodyContact::velocity_passes(const State& before, State& state, Real h) {
  const BodyContactParams& c = params_;
  const int np = static_cast<int>(inverse_mass_.size());
  const int count = static_cast<int>(contacts_.size());
  impulse_.resize(count);
  back_.resize(count);
  touching_.resize(count);
  bool approached = false;
  for (int pass = 0; pass < c.iterations; ++pass) {
    // The pairs that overlap and approach, and each particle's share of them.
    share_.assign(np, 0);
    bool any = false;
    for (int p = 0; p < count; ++p) {
      const int i = contacts_[p].first, j = contacts_[p].second;
      const Vec3 d = particle(state.x, j) - particle(state.x, i);
      const Real dist = d.norm();
      touching_[p] = radius_[i] + radius_[j] - dist > 0 && dist > 0 &&
                     (particle(state.v, j) - particle(state.v, i)).dot(d) < 0;
      if (!touching_[p]) continue;
      any = true;
      ++share_[i];
      ++share_[j];
    }
    if (!any) break;
    approached = true;
    // Each pair's impulse from this pass's state, with each particle's mass split among its
    // pairs: the pair collides as two particles of mass m_i / share_i, m_j / share_j.
    for (int p = 0; p < count; ++p) {
      if (!touching_[p]) continue;
      const int i = contacts_[p].first, j = contacts_[p].second;
      const Vec3 d = particle(state.x, j) - particle(state.x, i);
      const Vec3 n = d / d.norm();
      const Real wi = inverse_mass_[i] * share_[i], wj = inverse_mass_[j] * share_[j];
      const Real w = wi + wj;
      const Vec3 rel = particle(state.v, j) - particle(state.v, i);
      const Real vn = rel.dot(n);  // < 0
      // Absorb the approach, or reflect it if it was already there at the step's start.
      const Real approach_before = -(particle(before.v, j) - particle(before.v, i)).dot(n);
      const Real vn_new = approach_before > c.resting_speed ? -c.restitution * vn : 0.0;
      const Real dvn = vn_new - vn;  // > 0
      // Coulomb friction on the tangential relative velocity, bounded by mu dv_n.
      const Vec3 vt = rel - vn * n;
      const Real speed_t = vt.norm();
      const bool stick = speed_t <= c.static_friction * dvn;
      const Vec3 dvt = stick ? Vec3(-vt) : Vec3(-(c.friction * dvn / speed_t) * vt);
      // The split pair's relative velocity changes by dvn n + dvt: impulse P on j, -P on i.
      impulse_[p] = (dvn * n + dvt) / w;
      // Friction acts during the step: the tangential displacement it removes is taken back
      // too (as for a terrain): a sticking pair keeps its relative tangential position of the
      // step's start, a sliding one loses h dv_t. (After a sticking, absorbed contact the pair
      // moves together, so this changes no angular momentum.)
      if (stick) {
        const Vec3 slip = d - (particle(before.x, j) - particle(before.x, i));
        back_[p] = -(slip - slip.dot(n) * n) / w;
      } else {
        back_[p] = (h / w) * dvt;
      }
    }
    // Applied together, in pair order: each particle receives the sum of its pairs' impulses.
    for (int p = 0; p < count; ++p) {
      if (!touching_[p]) continue;
      const int i = contacts_[p].first, j = contacts_[p].second;
      const Real wi = inverse_mass_[i], wj = inverse_mass_[j];
      particle(state.v, i) -= wi * impulse_[p];
      particle(state.v, j) += wj * impulse_[p];
      particle(state.x, i) -= wi * back_[p];
      particle(state.x, j) += wj * back_[p];
    }
  }
  return approached;
}

void BodyContact::projection_passes(const Model& model, const VecX& x) {
  const int np = static_cast<int>(inverse_mass_.size());
  const int nb = model.num_bodies();
  const int count = static_cast<int>(contacts_.size());
  moved_.setZero(3 * np);
  shifted_.setZero(3 * np);
  body_shift_.assign(nb, Vec3::Zero());
  body_inverse_mass_.assign(nb, 0.0);
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    Real mass = 0;
    bool pinned = false;
    for (int i = body.first_particle; i < body.end_particle(); ++i) {
      mass += model.mass[i];
      pinned = pinned || inverse_mass_[i] == 0;
    }
    body_inverse_mass_[b] = pinned || !(mass > 0) ? 0.0 : 1.0 / mass;
  }
  // Where a pair's particles are in either projection so far.
  const auto by_particles = [&](int i) { return Vec3(particle(x, i) + particle(moved_, i)); };
  const auto by_bodies = [&](int i) {
    return Vec3(particle(x, i) + particle(shifted_, i) + body_shift_[body_[i]]);
  };
  const auto overlap = [&](int p, const auto& at, Vec3* n) {
    const int i = contacts_[p].first, j = contacts_[p].second;
    const Vec3 d = at(j) - at(i);
    const Real dist = d.norm();
    const Real o = radius_[i] + radius_[j] - dist;
    if (!(o > 0 && dist > 0)) return 0.0;
    *n = d / dist;
    return o;
  };
  for (int pass = 0; pass < params_.iterations; ++pass) {
    bool any = false;
    // Particles: each pair moves its two particles apart along the line of centres, the
    // particles' masses split among their overlapping pairs.
    share_.assign(np, 0);
    for (int p = 0; p < count; ++p) {
      Vec3 n = Vec3::UnitX();
      touching_[p] = overlap(p, by_particles, &n) > 0;
      if (!touching_[p]) continue;
      ++share_[contacts_[p].first];
      ++share_[contacts_[p].second];
    }
    for (int p = 0; p < count; ++p) {
      if (!touching_[p]) continue;
      any = true;
      const int i = contacts_[p].first, j = contacts_[p].second;
      Vec3 n = Vec3::UnitX();
      const Real o = overlap(p, by_particles, &n);
      const Real a = o / (inverse_mass_[i] * share_[i] + inverse_mass_[j] * share_[j]);
      impulse_[p] = a * n;
    }
    for (int p = 0; p < count; ++p) {
      if (!touching_[p]) continue;
      const int i = contacts_[p].first, j = contacts_[p].second;
      particle(moved_, i) -= inverse_mass_[i] * impulse_[p];
      particle(moved_, j) += inverse_mass_[j] * impulse_[p];
    }
    // Bodies: the pairs of two bodies move the bodies apart as wholes, each body's mass split
    // among its overlapping pairs; the pairs within one body (self-contact) move particles.
    share_.assign(np, 0);
    body_share_.assign(nb, 0);
    for (int p = 0; p < count; ++p) {
      Vec3 n = Vec3::UnitX();
      touching_[p] = overlap(p, by_bodies, &n) > 0;
      if (!touching_[p]) continue;
      const int i = contacts_[p].first, j = contacts_[p].second;
      if (body_[i] == body_[j]) {
        ++share_[i];
        ++share_[j];
      } else {
        ++body_share_[body_[i]];
        ++body_share_[body_[j]];
      }
    }
    for (int p = 0; p < count; ++p) {
      if (!touching_[p]) continue;
      any = true;
      const int i = contacts_[p].first, j = contacts_[p].second;
      Vec3 n = Vec3::UnitX();
      const Real o = overlap(p, by_bodies, &n);
      Real w;
      if (body_[i] == body_[j]) {
        w = inverse_mass_[i] * share_[i] + inverse_mass_[j] * share_[j];
      } else {
        w = body_inverse_mass_[body_[i]] * body_share_[body_[i]] +
            body_inverse_mass_[body_[j]] * body_share_[body_[j]];
      }
      impulse_[p] = w > 0 ? Vec3((o / w) * n) : Vec3::Zero();  // (two pinned bodies: none)
    }
    for (int p = 0; p < count; ++p) {
      if (!touching_[p]) continue;
      const int i = contacts_[p].first, j = contacts_[p].second;
      if (body_[i] == body_[j]) {
        particle(shifted_, i) -= inverse_mass_[i] * impulse_[p];
        particle(shifted_, j) += inverse_mass_[j] * impulse_[p];
      } else {
        body_shift_[body_[i]] -= body_inverse_mass_[body_[i]] * impulse_[p];
        body_shift_[body_[j]] += body_inverse_mass_[body_[j]] * impulse_[p];
      }
    }
    if (!any) break;
  }
  for (int b = 0; b < nb; ++b) {
    if (body_shift_[b].isZero()) continue;
    const Body& body = model.bodies[b];
    for (int i = body.first_particle; i < body.end_particle(); ++i)
      particle(shifted_, i) += body_shift_[b];
  }
}

void BodyContact::blend(const Model& model, Real share, const VecX& x, const VecX& v, State& out) {
  const int np = model.num_particles();
  out.x = x + share * moved_ + (1 - share) * shifted_;
  out.v = v;
  // The projection moved particles without changing their velocities, which changes the
  // angular momentum by dL = sum m_i dx_i x v_i. It is taken back by tangential impulses Q_p on
  // the pairs (Q_p on j, -Q_p on i, torque d_p x Q_p with d_p = x_j - x_i after the
  // projection), the smallest that do it: Q_p = mu x d_p with K mu = -dL,
  // K = sum_p (|d_p|^2 I - d_p d_p^T) (solved on K's range: with all d_p parallel, dL has no
  // part along them).
  Vec3 dl = Vec3::Zero();
  for (int i = 0; i < np; ++i) {
    const Vec3 dx = particle(out.x, i) - particle(x, i);
    if (!dx.isZero()) dl += model.mass[i] * dx.cross(particle(v, i));
  }
  if (dl.isZero()) return;
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  for (const BroadPhase::Pair& p : contacts_) {
    if (inverse_mass_[p.first] + inverse_mass_[p.second] <= 0) continue;
    const Vec3 d = particle(out.x, p.second) - particle(out.x, p.first);
    k += d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(k);
  const Real largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0)) return;
  Vec3 inverse = Vec3::Zero();
  for (int e = 0; e < 3; ++e) {
    const Real value = eigen.eigenvalues()[e];
    if (value > 1e-12 * largest) inverse[e] = 1 / value;
  }
  const Vec3 mu =
      eigen.eigenvectors() * inverse.asDiagonal() * (eigen.eigenvectors().transpose() * -dl);
  for (const BroadPhase::Pair& p : contacts_) {
    const int i = p.first, j = p.second;
    const Real wi = inverse_mass_[i], wj = inverse_mass_[j];
    if (wi + wj <= 0) continue;
    const Vec3 d = particle(out.x, j) - particle(out.x, i);
    // (A pinned particle takes no velocity: its partner takes the pair's whole torque, its
    // lever measured from the pin.)
    const Vec3 q = mu.cross(d);
    if (wi > 0 && wj > 0) {
      particle(out.v, i) -= q / model.mass[i];
      particle(out.v, j) += q / model.mass[j];
    } else if (wj > 0) {
      particle(out.v, j) += q / model.mass[j];
    } else {
      particle(out.v, i) -= q / model.mass[i];
    }
  }
}

void BodyContact::resolve(const Model& model, const State& before, State& state, Real h) {
  contacts_.clear();
  if (!active(model)) return;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  prepare(model);
  broad_.find_pairs(state.x, radius_, candidates_);
  const auto t1 = Clock::now();
  filter(model);
  if (!contacts_.empty()) {
    // Velocities first (the positions stay, but for friction's take-back), then the projection
    // from the positions they leave.
    velocity_passes(before, state, h);
    projection_passes(model, state.x);
    if (!moved_.isZero() || !shifted_.isZero()) {
      start_.t = state.t;
      start_.x = state.x;
      start_.v = state.v;
      // The energy at the start of the step bounds the energy after the contact: the
      // particles' projection as far as it keeps within it. If even the translations exceed it
      // (the step itself gained energy: work of pins or external forces, an integrator that
      // does not dissipate; or gravity's work on lifted bodies), the translations are taken:
      // the overlap is still removed, with the least elastic work.
      const Real budget = total_energy(model, before);
      const Real scale = std::max(std::abs(budget), kinetic_energy(model, before.v));
      const auto fits = [&](Real share) {
        blend(model, share, start_.x, start_.v, state);
        return total_energy(model, state) <= budget + 1e-12 * scale;
      };
      if (!fits(1)) {
        ++stats_.limited;
        Real lo = 0, hi = 1;
        if (fits(0)) {
          for (int k = 0; k < 12; ++k) {
            const Real mid = 0.5 * (lo + hi);
            (fits(mid) ? lo : hi) = mid;
          }
        }
        blend(model, lo, start_.x, start_.v, state);
      }
    }
  }
  const auto t2 = Clock::now();
  stats_.pairs += static_cast<long>(contacts_.size());
  stats_.broad_seconds += std::chrono::duration<double>(t1 - t0).count();
  stats_.narrow_seconds += std::chrono::duration<double>(t2 - t1).count();
  ++stats_.steps;
}

}  // namespace jelly
