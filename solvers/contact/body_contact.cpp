#include <jelly/solvers/contact/body_contact.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Eigenvalues>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

namespace jelly {

void BodyContactParams::validate(const std::string& prefix) const {
  require(std::isfinite(restitution) && restitution >= 0 && restitution <= 1,
          prefix + "restitution", restitution, "a number in [0, 1]");
  require(std::isfinite(friction) && friction >= 0, prefix + "friction", friction,
          "a finite number >= 0");
  require(std::isfinite(static_friction) && static_friction >= friction, prefix + "static_friction",
          static_friction, "a finite number >= friction (" + to_text(friction) + ")");
  require(std::isfinite(resting_speed) && resting_speed >= 0, prefix + "resting_speed",
          resting_speed, "a finite speed >= 0");
  require(iterations >= 1 && iterations <= 100, prefix + "iterations", iterations,
          "an integer in [1, 100]");
}

BodyContactParams BodyContactParams::read(JsonFields& f) {
  BodyContactParams p;
  p.enabled = f.boolean_or("enabled", p.enabled);
  p.self_contact = f.boolean_or("self_contact", p.self_contact);
  p.restitution = f.number_or("restitution", p.restitution);
  p.friction = f.number_or("friction", p.friction);
  p.static_friction = f.number_or("static_friction", std::max(p.static_friction, p.friction));
  p.resting_speed = f.number_or("resting_speed", p.resting_speed);
  p.iterations = f.integer_or("iterations", p.iterations);
  f.reject_unknown();
  p.validate(f.prefix());
  return p;
}

Json BodyContactParams::to_json() const {
  Json j;
  j["enabled"] = enabled;
  j["self_contact"] = self_contact;
  j["restitution"] = restitution;
  j["friction"] = friction;
  j["static_friction"] = static_friction;
  j["resting_speed"] = resting_speed;
  j["iterations"] = iterations;
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
  if (prepared_for_ == &model && prepared_particles_ == n &&
      prepared_springs_ == model.springs.size())
    return;
  prepared_for_ = &model;
  prepared_particles_ = n;
  prepared_springs_ = model.springs.size();
  radius_.resize(n);
  inverse_mass_ = model.mass.cwiseInverse();
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
  for (int k = 0; k < model.pins.size(); ++k) inverse_mass_[model.pins.particles[k]] = 0;
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
  spring_start_ = neighbour_start_;
  springs_at_.resize(neighbours_.size());
  fill.assign(spring_start_.begin(), spring_start_.end() - 1);
  for (int k = 0; k < s.size(); ++k) {
    springs_at_[fill[s.a[k]]++] = k;
    springs_at_[fill[s.b[k]]++] = k;
  }
  is_touched_.assign(n, 0);
}

Real BodyContact::touched_energy(const Model& model, const VecX& x, const VecX& v) const {
  const Springs& s = model.springs;
  Real e = 0;
  for (int i : touched_) {
    e += 0.5 * model.mass[i] * particle(v, i).squaredNorm();
    for (int q = spring_start_[i]; q < spring_start_[i + 1]; ++q) {
      const int k = springs_at_[q];
      const int other = s.a[k] == i ? s.b[k] : s.a[k];
      if (is_touched_[other] && other < i) continue;  // counted at its other end
      const Real stretch = (particle(x, s.a[k]) - particle(x, s.b[k])).norm() - s.rest_length[k];
      e += 0.5 * s.ks[k] * stretch * stretch;
    }
  }
  return e;
}

void BodyContact::limit_projection(const Model& model, State& state, Real budget, Real tolerance) {
  const int m = static_cast<int>(touched_.size());
  x_resolved_.resize(3 * static_cast<size_t>(m));
  // (Workspace of the rare limited resolve, no allocation once sized.)
  thread_local std::vector<Real> v_resolved;
  v_resolved.resize(3 * static_cast<size_t>(m));
  for (int t = 0; t < m; ++t) {
    for (int q = 0; q < 3; ++q) {
      x_resolved_[3 * t + q] = state.x[3 * touched_[t] + q];
      v_resolved[3 * t + q] = state.v[3 * touched_[t] + q];
    }
  }
  ++stats_.projections_limited;
  // The touched particles' angular momentum after the resolve (which conserved it, less
  // friction's torque): a shortened projection loses the lever it compensated, which a rigid
  // rotation of the touched particles' velocities about their centre of mass gives back
  // exactly (it changes no linear momentum).
  const auto angular = [&](bool resolved) {
    Vec3 l = Vec3::Zero();
    for (int t = 0; t < m; ++t) {
      const int i = touched_[t];
      const Vec3 x = resolved
                         ? Vec3(x_resolved_[3 * t], x_resolved_[3 * t + 1], x_resolved_[3 * t + 2])
                         : Vec3(particle(state.x, i));
      l += model.mass[i] * x.cross(Vec3(particle(state.v, i)));
    }
    return l;
  };
  const Vec3 target = angular(true);
  const auto give_back_angular_momentum = [&]() {
    Real total = 0;
    Vec3 centre = Vec3::Zero();
    for (int i : touched_) {
      if (inverse_mass_[i] == 0) continue;  // a pin takes no part
      total += model.mass[i];
      centre += model.mass[i] * particle(state.x, i);
    }
    if (!(total > 0)) return;
    centre /= total;
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    for (int i : touched_) {
      if (inverse_mass_[i] == 0) continue;
      const Vec3 r = particle(state.x, i) - centre;
      inertia +=
          model.mass[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    }
    // The pseudo-inverse (particles on a line cannot spin about it).
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(inertia);
    const Vec3 error = angular(false) - target;
    const Vec3 e = eigen.eigenvectors().transpose() * error;
    const Real largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
    Vec3 w = Vec3::Zero();
    for (int q = 0; q < 3; ++q) {
      if (eigen.eigenvalues()[q] > 1e-12 * largest) w[q] = -e[q] / eigen.eigenvalues()[q];
    }
    const Vec3 omega = eigen.eigenvectors() * w;
    for (int i : touched_) {
      if (inverse_mass_[i] > 0) particle(state.v, i) += omega.cross(particle(state.x, i) - centre);
    }
  };
  // Halve the projection until the energy fits; none at all fits (the impulses alone never add
  // kinetic energy) when the rotation is left out. (The rotation makes the limited resolve
  // conserve angular momentum as the full one does.)
  Real scale = 1;
  for (int halving = 0; halving <= 11; ++halving) {
    scale = halving >= 10 ? 0.0 : scale * 0.5;
    for (int t = 0; t < m; ++t) {
      for (int q = 0; q < 3; ++q) {
        const Real entry = x_entry_[3 * t + q];
        state.x[3 * touched_[t] + q] = entry + scale * (x_resolved_[3 * t + q] - entry);
        state.v[3 * touched_[t] + q] = v_resolved[3 * t + q];
      }
    }
    if (halving <= 10) give_back_angular_momentum();
    if (touched_energy(model, state.x, state.v) <= budget + tolerance) return;
  }
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

void BodyContact::resolve(const Model& model, const State& before, State& state, Real h) {
  contacts_.clear();
  if (!active(model)) return;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  prepare(model);
  broad_.find_pairs(state.x, radius_, candidates_);
  const auto t1 = Clock::now();
  filter(model);
  // The particles the pairs touch, their energy at the step's start and now, and where they are.
  touched_.clear();
  for (const BroadPhase::Pair& p : contacts_) {
    for (const int i : {p.first, p.second}) {
      if (is_touched_[i]) continue;
      is_touched_[i] = 1;
      touched_.push_back(i);
    }
  }
  const auto kinetic = [&](const VecX& v) {
    Real k = 0;
    for (int i : touched_) k += 0.5 * model.mass[i] * particle(v, i).squaredNorm();
    return k;
  };
  // The budget: the kinetic energy on entry (the impulses only take from it) and the larger of
  // the springs' energies at the step's start and on entry (a resting body put back where it was
  // at the step's start restores springs the step relaxed; never more than they had).
  const Real kinetic_entry = kinetic(state.v);
  const Real energy_before = touched_energy(model, before.x, before.v);
  const Real energy_entry = touched_energy(model, state.x, state.v);
  const Real budget =
      kinetic_entry + std::max(energy_before - kinetic(before.v), energy_entry - kinetic_entry);
  x_entry_.resize(3 * touched_.size());
  for (size_t t = 0; t < touched_.size(); ++t) {
    for (int q = 0; q < 3; ++q) x_entry_[3 * t + q] = state.x[3 * touched_[t] + q];
  }
  const BodyContactParams& c = params_;
  // Sequential impulses: every pass resolves each pair with the current positions and velocities.
  for (int pass = 0; pass < c.iterations; ++pass) {
    bool any = false;
    for (const BroadPhase::Pair& p : contacts_) {
      const int i = p.first, j = p.second;
      auto xi = particle(state.x, i);
      auto xj = particle(state.x, j);
      auto vi = particle(state.v, i);
      auto vj = particle(state.v, j);
      const Vec3 d = xj - xi;
      const Real dist = d.norm();
      const Real overlap = radius_[i] + radius_[j] - dist;
      if (overlap <= 0 || dist <= 0) continue;
      any = true;
      const Vec3 n = d / dist;
      const Real wi = inverse_mass_[i], wj = inverse_mass_[j], w = wi + wj;
      // Normal: absorb the approach, or reflect it if it was already there at the step's start.
      const Vec3 rel = vj - vi;
      const Real vn = rel.dot(n);
      if (vn < 0) {
        const Real approach_before = -(particle(before.v, j) - particle(before.v, i)).dot(n);
        const Real vn_new = approach_before > c.resting_speed ? -c.restitution * vn : 0.0;
        const Real dvn = vn_new - vn;  // > 0
        // Coulomb friction on the tangential relative velocity, bounded by mu dv_n.
        const Vec3 vt = rel - vn * n;
        const Real speed_t = vt.norm();
        const bool stick = speed_t <= c.static_friction * dvn;
        const Vec3 dvt = stick ? Vec3(-vt) : Vec3(-(c.friction * dvn / speed_t) * vt);
        // Relative velocity change dv = dvn n + dvt from the impulse P on j (-P on i).
        const Vec3 impulse = (dvn * n + dvt) / w;
        vi -= wi * impulse;
        vj += wj * impulse;
        // Friction acts during the step: the tangential displacement it removes is taken back
        // too (as for a terrain): a sticking pair keeps its relative tangential position of the
        // step's start, a sliding one loses h dv_t. (After a sticking, absorbed contact the pair
        // moves together, so this changes no angular momentum.)
        Vec3 back;
        if (stick) {
          const Vec3 slip = d - (particle(before.x, j) - particle(before.x, i));
          back = -(slip - slip.dot(n) * n);
        } else {
          back = h * dvt;
        }
        xi -= (wi / w) * back;
        xj += (wj / w) * back;
      }
      // Projection along the line of centres (as they are now); the lever it adds to the pair
      // would change the angular momentum by a n x (v_j - v_i): a tangential impulse takes it
      // back exactly.
      const Vec3 d1 = xj - xi;
      const Real dist1 = d1.norm();
      const Real overlap1 = radius_[i] + radius_[j] - dist1;
      if (overlap1 <= 0 || dist1 <= 0) continue;
      const Vec3 n1 = d1 / dist1;
      const Real a = overlap1 / w;
      xi -= (a * wi) * n1;
      xj += (a * wj) * n1;
      const Vec3 rel_after = vj - vi;
      const Vec3 tangential = rel_after - rel_after.dot(n1) * n1;
      const Vec3 q = (-a / (dist1 + overlap1)) * tangential;
      vi -= wi * q;
      vj += wj * q;
    }
    if (!any) break;
  }
  if (!contacts_.empty()) {
    const Real tolerance = 1e-12 * (energy_before + energy_entry);
    if (touched_energy(model, state.x, state.v) > budget + tolerance)
      limit_projection(model, state, budget, tolerance);
  }
  for (int i : touched_) is_touched_[i] = 0;
  const auto t2 = Clock::now();
  stats_.pairs += static_cast<long>(contacts_.size());
  stats_.broad_seconds += std::chrono::duration<double>(t1 - t0).count();
  stats_.narrow_seconds += std::chrono::duration<double>(t2 - t1).count();
  ++stats_.steps;
}

}  // namespace jelly
