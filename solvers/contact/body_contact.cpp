#include <jelly/solvers/contact/detail/body_contact.hpp>

#include <Eigen/Geometry>
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

// collide()'s reach beyond the velocity's travel, as a share of the radius (at least the
// margin implicit_euler's candidates take, kCandidateMargin, so that they fit within it).
constexpr Real kCollideShare = 0.3;
// The share of its reach a particle may travel for resolve() to keep collide()'s set.
constexpr Real kCollideTravel = 0.99;

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
  // The springs of each particle (CSR, in spring order), and the springs whose ends are in
  // different bodies (a translation of one body changes their length).
  spring_start_ = neighbour_start_;
  springs_of_.resize(neighbours_.size());
  std::copy(neighbour_start_.begin(), neighbour_start_.end() - 1, fill.begin());
  cross_springs_.clear();
  for (int k = 0; k < s.size(); ++k) {
    springs_of_[fill[s.a[k]]++] = k;
    springs_of_[fill[s.b[k]]++] = k;
    if (body_[s.a[k]] != body_[s.b[k]]) cross_springs_.push_back(k);
  }
  particle_mark_.assign(n, 0);
  spring_mark_.assign(s.size(), 0);
  blend_v_.setZero(3 * n);
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
  // In one order whichever search found them (the broad phase's order depends on its grid):
  // the response sums over pairs, so collide()'s set and a search give the same bits.
  std::sort(contacts_.begin(), contacts_.end());
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

void BodyContact::collide(const Model& model, const State& state, Real h) {
  collisions_fresh_ = false;
  collisions_.clear();
  if (!active(model)) return;
  const auto t0 = std::chrono::steady_clock::now();
  prepare(model);
  const int n = model.num_particles();
  const Real fall = 2 * h * h * model.gravity.norm();
  reach_.resize(n);
  padded_.resize(n);
  for (int i = 0; i < n; ++i) {
    reach_[i] = radius_[i] > 0
                    ? kCollideShare * radius_[i] + 2 * h * particle(state.v, i).norm() + fall
                    : 0;
    padded_[i] = radius_[i] + reach_[i];
  }
  if (padded_.allFinite()) {
    broad_.find_pairs(state.x, padded_, candidates_);
    filter(model);
    collisions_.swap(contacts_);
    contacts_.clear();
    collided_x_ = state.x;
    collisions_fresh_ = true;
  }
  stats_.broad_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool BodyContact::take_collisions(const VecX& x) {
  const bool fresh = collisions_fresh_ && collided_x_.size() == x.size() &&
                     std::equal(x.data(), x.data() + x.size(), collided_x_.data());
  collisions_fresh_ = false;
  return fresh;
}

void BodyContact::select_collisions(const VecX& x, const VecX* pad) {
  contacts_.clear();
  for (const BroadPhase::Pair& p : collisions_) {
    const int i = p.first, j = p.second;
    if (inverse_mass_[i] + inverse_mass_[j] <= 0) continue;  // two pins
    const Real ri = pad != nullptr ? (*pad)[i] : radius_[i];
    const Real rj = pad != nullptr ? (*pad)[j] : radius_[j];
    const Real reach = ri + rj;
    const Vec3 d(x[3 * j] - x[3 * i], x[3 * j + 1] - x[3 * i + 1], x[3 * j + 2] - x[3 * i + 2]);
    if (d.squaredNorm() < reach * reach) contacts_.push_back(p);
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
  // collide()'s set holds every pair these spheres make when none is larger than its sphere
  // there.
  bool covered = take_collisions(x);
  for (int i = 0; covered && i < padded_.size(); ++i)
    covered = padded_[i] <= radius_[i] + reach_[i];
  if (covered) {
    select_collisions(x, &padded_);
    ++stats_.collided;
  } else {
    broad_.find_pairs(x, padded_, candidates_);
    filter(model);
    ++stats_.searched;
  }
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

void BodyContact::prepare_blend(const Model& model) {
  const int np = model.num_particles();
  // Only the pairs' particles move apart from their body's translation (moved_, and shifted_
  // of self-contact pairs) and take the lever's impulses: their springs, and the springs
  // between bodies, are the only ones a blend stretches.
  blend_particles_.clear();
  blend_springs_.clear();
  const auto add_spring = [&](int k) {
    if (spring_mark_[k]) return;
    spring_mark_[k] = 1;
    blend_springs_.push_back(k);
  };
  for (const BroadPhase::Pair& p : contacts_) {
    for (const int i : {p.first, p.second}) {
      if (particle_mark_[i]) continue;
      particle_mark_[i] = 1;
      blend_particles_.push_back(i);
      for (int e = spring_start_[i]; e < spring_start_[i + 1]; ++e) add_spring(springs_of_[e]);
    }
  }
  for (const int k : cross_springs_) add_spring(k);
  for (const int i : blend_particles_) particle_mark_[i] = 0;
  for (const int k : blend_springs_) spring_mark_[k] = 0;
  // The projection moved particles without changing their velocities, which changes the
  // angular momentum by dL = sum m_i dx_i x v_i, dx = share moved + (1 - share) shifted: linear
  // in the share. Gravity's energy -sum m_i g . dx_i too. moved_ is zero but at the pairs'
  // particles; shifted_ holds the bodies' translations.
  lever_moved_.setZero();
  lever_shifted_.setZero();
  gravity_moved_ = 0;
  gravity_shifted_ = 0;
  for (const int i : blend_particles_) {
    const Vec3 m = particle(moved_, i);
    lever_moved_ += model.mass[i] * m.cross(Vec3(particle(start_.v, i)));
    gravity_moved_ -= model.mass[i] * model.gravity.dot(m);
  }
  for (int i = 0; i < np; ++i) {
    const Vec3 s = particle(shifted_, i);
    if (s.isZero()) continue;
    lever_shifted_ += model.mass[i] * s.cross(Vec3(particle(start_.v, i)));
    gravity_shifted_ -= model.mass[i] * model.gravity.dot(s);
  }
  // The pairs' and springs' vectors x_b - x_a as lines in the share; the energy the blend
  // changes measured from start_'s kinetic energy of the pairs' particles and elastic energy
  // of their springs.
  const auto line = [&](int a, int b) {
    return BlendLine{Vec3(particle(start_.x, b) - particle(start_.x, a)),
                     Vec3(particle(moved_, b) - particle(moved_, a)),
                     Vec3(particle(shifted_, b) - particle(shifted_, a))};
  };
  pair_lines_.resize(contacts_.size());
  pair_d_.resize(contacts_.size());
  for (size_t p = 0; p < contacts_.size(); ++p)
    pair_lines_[p] = line(contacts_[p].first, contacts_[p].second);
  blend_start_energy_ = 0;
  for (const int i : blend_particles_)
    blend_start_energy_ += 0.5 * model.mass[i] * particle(start_.v, i).squaredNorm();
  const Springs& s = model.springs;
  spring_lines_.resize(blend_springs_.size());
  for (size_t e = 0; e < blend_springs_.size(); ++e) {
    const int k = blend_springs_[e];
    spring_lines_[e] = line(s.a[k], s.b[k]);
    const Real stretch = spring_lines_[e].at_start.norm() - s.rest_length[k];
    blend_start_energy_ += 0.5 * s.ks[k] * stretch * stretch;
  }
}

Vec3 BodyContact::lever_multiplier(const Vec3& dl) const {
  // dL is taken back by tangential impulses Q_p on the pairs (Q_p on j, -Q_p on i, torque
  // d_p x Q_p with d_p = x_j - x_i after the projection), the smallest that do it:
  // Q_p = mu x d_p with K mu = -dL, K = sum_p (|d_p|^2 I - d_p d_p^T) (solved on K's range: with
  // all d_p parallel, dL has no part along them).
  if (dl.isZero()) return Vec3::Zero();
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  for (size_t p = 0; p < contacts_.size(); ++p) {
    if (inverse_mass_[contacts_[p].first] + inverse_mass_[contacts_[p].second] <= 0) continue;
    const Vec3& d = pair_d_[p];
    k += d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(k);
  const Real largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0)) return Vec3::Zero();
  Vec3 inverse = Vec3::Zero();
  for (int e = 0; e < 3; ++e) {
    const Real value = eigen.eigenvalues()[e];
    if (value > 1e-12 * largest) inverse[e] = 1 / value;
  }
  return eigen.eigenvectors() * inverse.asDiagonal() * (eigen.eigenvectors().transpose() * -dl);
}

namespace {
// The lever's impulses mu x d_p on the pairs, applied to velocities v (a pinned particle takes
// no velocity: its partner takes the pair's whole torque, its lever measured from the pin).
void apply_lever_impulses(const Model& model, const std::vector<BroadPhase::Pair>& pairs,
                          const VecX& inverse_mass, const Vec3& mu, const std::vector<Vec3>& d,
                          VecX& v) {
  for (size_t p = 0; p < pairs.size(); ++p) {
    const int i = pairs[p].first, j = pairs[p].second;
    const Real wi = inverse_mass[i], wj = inverse_mass[j];
    if (wi + wj <= 0) continue;
    const Vec3 q = mu.cross(d[p]);
    if (wi > 0 && wj > 0) {
      particle(v, i) -= q / model.mass[i];
      particle(v, j) += q / model.mass[j];
    } else if (wj > 0) {
      particle(v, j) += q / model.mass[j];
    } else {
      particle(v, i) -= q / model.mass[i];
    }
  }
}
}  // namespace

void BodyContact::blend(const Model& model, Real share, State& out) {
  out.x = start_.x + share * moved_ + (1 - share) * shifted_;
  out.v = start_.v;
  Vec3 dl = Vec3::Zero();
  for (int i = 0; i < model.num_particles(); ++i) {
    const Vec3 dx = particle(out.x, i) - particle(start_.x, i);
    if (!dx.isZero()) dl += model.mass[i] * dx.cross(particle(start_.v, i));
  }
  pair_d_.resize(contacts_.size());
  for (size_t p = 0; p < contacts_.size(); ++p)
    pair_d_[p] = particle(out.x, contacts_[p].second) - particle(out.x, contacts_[p].first);
  const Vec3 mu = lever_multiplier(dl);
  if (!mu.isZero()) apply_lever_impulses(model, contacts_, inverse_mass_, mu, pair_d_, out.v);
}

Real BodyContact::blend_energy_change(const Model& model, Real share) {
  // Kinetic: the velocities blend() gives the pairs' particles.
  for (const int i : blend_particles_) particle(blend_v_, i) = particle(start_.v, i);
  for (size_t p = 0; p < contacts_.size(); ++p) pair_d_[p] = pair_lines_[p].at(share);
  const Vec3 mu = lever_multiplier(share * lever_moved_ + (1 - share) * lever_shifted_);
  if (!mu.isZero()) apply_lever_impulses(model, contacts_, inverse_mass_, mu, pair_d_, blend_v_);
  Real energy = share * gravity_moved_ + (1 - share) * gravity_shifted_;
  for (const int i : blend_particles_)
    energy += 0.5 * model.mass[i] * particle(blend_v_, i).squaredNorm();
  // Elastic: ks (|xa - xb| - l0)^2 / 2 of the springs the blend stretches.
  const Springs& s = model.springs;
  for (size_t e = 0; e < blend_springs_.size(); ++e) {
    const int k = blend_springs_[e];
    const Real stretch = spring_lines_[e].at(share).norm() - s.rest_length[k];
    energy += 0.5 * s.ks[k] * stretch * stretch;
  }
  return energy - blend_start_energy_;
}

void BodyContact::resolve(const Model& model, const State& before, State& state, Real h) {
  contacts_.clear();
  if (!active(model)) return;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  prepare(model);
  // collide()'s set holds every pair in contact at the end when no particle travelled beyond
  // its reach (with a share of it for round-off): the distance of two spheres shrank by at
  // most the sum of their travels.
  bool covered = take_collisions(before.x);
  for (int i = 0; covered && i < model.num_particles(); ++i) {
    covered = radius_[i] <= 0 ||
              (particle(state.x, i) - particle(before.x, i)).norm() <= kCollideTravel * reach_[i];
  }
  if (covered) {
    select_collisions(state.x, nullptr);
    ++stats_.collided;
  } else {
    broad_.find_pairs(state.x, radius_, candidates_);
    ++stats_.searched;
  }
  const auto t1 = Clock::now();
  if (!covered) filter(model);
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
      // Most steps take the particles' projection whole: its energy summed over the model.
      blend(model, 1, state);
      if (!(total_energy(model, state) <= budget + 1e-12 * scale)) {
        ++stats_.limited;
        // The bisection's blends: start_'s energy, summed once over the model, plus what each
        // blend changes, summed over the pairs' particles and springs.
        const Real start_energy = total_energy(model, start_);
        prepare_blend(model);
        const auto fits = [&](Real share) {
          return start_energy + blend_energy_change(model, share) <= budget + 1e-12 * scale;
        };
        Real lo = 0, hi = 1;
        if (fits(0)) {
          for (int k = 0; k < 12; ++k) {
            const Real mid = 0.5 * (lo + hi);
            (fits(mid) ? lo : hi) = mid;
          }
        }
        blend(model, lo, state);
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
