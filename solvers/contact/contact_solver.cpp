#include <jelly/solvers/contact/contact_solver.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

namespace {

// Coulomb model: projection out of the surface, then an impulse on the relative velocity.
// Normal: restitution e when the particle approached faster than the resting speed at the start
// of the step (v_before), else the normal relative speed is absorbed.
// Tangential: sticks when |v_t| <= mu_s dv_n, else slides with |v_t| reduced by mu dv_n, so the
// friction impulse never exceeds mu times the normal impulse. Friction acts during the step, so
// the tangential displacement it removes is taken back too: a sticking particle keeps its
// tangential position relative to the surface (x_before + u h), a sliding one loses h dv_t.
// Without that, the velocity-level friction leaves a creep of h a_t / 2 per unit time.
bool resolve_coulomb(const Terrain& terrain, const ContactParams& c, Real t, Real h,
                     const Vec3& x_before, const Vec3& v_before, Eigen::Ref<Vec3> x,
                     Eigen::Ref<Vec3> v) {
  const Real d = terrain.signed_distance(x, t);
  if (d >= 0 || !terrain.can_contact(x, t)) return false;
  const Vec3 n = terrain.normal(x, t);
  const Vec3 u = terrain.surface_velocity(x, t);
  x -= d * n;
  const Vec3 relative = v - u;
  const Real vn = relative.dot(n);
  if (vn >= 0) return true;
  const bool impact = -(v_before - u).dot(n) > c.resting_speed;
  const Real vn_new = impact ? -c.restitution * vn : 0.0;
  const Real dvn = vn_new - vn;
  Vec3 vt = relative - vn * n;
  const Real speed_t = vt.norm();
  if (speed_t <= c.static_friction * dvn) {
    const Vec3 slip = x - x_before - h * u;
    x -= slip - slip.dot(n) * n;
    vt.setZero();
  } else {
    const Real keep = 1.0 - c.friction * dvn / speed_t;
    x -= h * (1.0 - keep) * vt;
    vt *= keep;
  }
  v = u + vn_new * n + vt;
  return true;
}

// Seed rules' collision test (report 1.2 / 1.3): within epsilon of the surface and moving
// towards it (relative velocity). Gives the surface's normal and velocity.
bool seed_touches(const Terrain& terrain, const ContactParams& c, Real t, const Vec3& x,
                  const Vec3& v, Vec3& n, Vec3& u) {
  if (terrain.signed_distance(x, t) >= c.epsilon || !terrain.can_contact(x, t)) return false;
  n = terrain.normal(x, t);
  u = terrain.surface_velocity(x, t);
  return (v - u).dot(n) < 0;
}

// Seed model: within epsilon and approaching, the normal velocity u1 becomes
// (m1 u1 + m2 u2 + m2 e (u2 - u1)) / (m1 + m2), u2 the surface's; a fixed plane (m2 infinite)
// gives u2 + e (u2 - u1) = -e u1. The tangential velocity is kept.
bool resolve_seed(const Terrain& terrain, const ContactParams& c, Real m1, Real t,
                  Eigen::Ref<const Vec3> x, Eigen::Ref<Vec3> v, Vec3& normal) {
  Vec3 n, u;
  if (!seed_touches(terrain, c, t, x, v, n, u)) return false;
  const Real u1 = v.dot(n);
  const Real u2 = u.dot(n);
  const Real m2 = terrain.mass();
  const Real e = c.restitution;
  const Real u1_new =
      std::isinf(m2) ? u2 + e * (u2 - u1) : (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2);
  v += (u1_new - u1) * n;
  normal = n;
  return true;
}

}  // namespace

void ContactSolver::resolve(const Model& model, const Terrains& terrains, const State& before,
                            State& state, Real h, Scope scope, int threads) {
  seed_contacts_.clear();
  contact_count_ = 0;
  const int np = model.num_particles();
  const int team = parallel::team_size(threads, np, parallel::kMinParticlesPerThread);
  if (static_cast<int>(part_count_.size()) < team) {
    part_seed_.resize(team);
    part_count_.resize(team);
  }
  for (const auto& terrain : terrains) {
    const ContactParams& c = terrain->contact();
    if (scope == Scope::kSeedOnly && c.model == ContactModel::kCoulomb) continue;
    int parts_used = 1;
    parallel::run(team, [&](int part, int parts) {
      if (part == 0) parts_used = parts;
      const parallel::Range r = parallel::split(np, part, parts);
      std::vector<SeedContact>& seed = part_seed_[part];
      int count = 0;
      seed.clear();
      for (int i = static_cast<int>(r.begin); i < static_cast<int>(r.end); ++i) {
        auto x = particle(state.x, i);
        auto v = particle(state.v, i);
        if (c.model == ContactModel::kSeedFramework) {
          // Nothing after the step: the next step's first force evaluation handles the
          // particles counted here (within epsilon and approaching).
          Vec3 n, u;
          count += seed_touches(*terrain, c, state.t, x, v, n, u);
        } else if (c.model == ContactModel::kCoulomb) {
          count += resolve_coulomb(*terrain, c, state.t, h, particle(before.x, i),
                                   particle(before.v, i), x, v);
        } else {
          Vec3 n;
          if (resolve_seed(*terrain, c, model.mass[i], state.t, x, v, n)) {
            ++count;
            seed.push_back({i, n, c.friction});
          }
        }
      }
      part_count_[part] = count;
    });
    for (int part = 0; part < parts_used; ++part) {
      contact_count_ += part_count_[part];
      seed_contacts_.insert(seed_contacts_.end(), part_seed_[part].begin(), part_seed_[part].end());
    }
  }
}

void ContactSolver::add_forces(const VecX& v, VecX& f) const {
  add_forces(v, f, 0, std::numeric_limits<int>::max());
}

void ContactSolver::add_forces(const VecX& v, VecX& f, int begin, int end) const {
  for (const SeedContact& c : seed_contacts_) {
    if (c.particle < begin || c.particle >= end) continue;
    auto fi = particle(f, c.particle);
    const Real fn = fi.dot(c.normal);
    if (fn >= 0) continue;
    const Vec3 vi = particle(v, c.particle);
    const Vec3 vt = vi - vi.dot(c.normal) * c.normal;
    // Contact force -(f.n) n cancels the push; friction -mu N v_t with N = -(f.n).
    fi += -fn * c.normal + c.friction * fn * vt;
  }
}

void ContactSolver::apply_in_evaluation(const Model& model, const Terrains& terrains, Real t,
                                        const VecX& x, VecX& v, VecX& f) {
  for (const auto& terrain : terrains) {
    const ContactParams& c = terrain->contact();
    if (c.model != ContactModel::kSeedFramework) continue;
    for (int i = 0; i < model.num_particles(); ++i) {
      auto vi = particle(v, i);
      Vec3 n;
      if (!resolve_seed(*terrain, c, model.mass[i], t, particle(x, i), vi, n)) continue;
      auto fi = particle(f, i);
      const Real fn = fi.dot(n);
      if (fn >= 0) continue;
      // The tangential velocity is the one before the reflection (which keeps it).
      const Vec3 vt = vi - vi.dot(n) * n;
      fi += -fn * n + c.friction * fn * vt;
    }
  }
}

bool ContactSolver::has_in_evaluation_contact(const Terrains& terrains) {
  for (const auto& terrain : terrains)
    if (terrain->contact().model == ContactModel::kSeedFramework) return true;
  return false;
}

void ContactSolver::clear() {
  seed_contacts_.clear();
  contact_count_ = 0;
}

void ContactSolver::restore(std::vector<SeedContact> seed_contacts, int contact_count) {
  seed_contacts_ = std::move(seed_contacts);
  contact_count_ = contact_count;
}

std::vector<std::string> seed_step_warnings(const Model& model, const State& state,
                                            const Terrains& terrains, Real dt, Real t_end) {
  std::vector<std::string> out;
  for (size_t k = 0; k < terrains.size(); ++k) {
    const Terrain& terrain = *terrains[k];
    const ContactParams& c = terrain.contact();
    if (!is_seed_model(c.model) || model.num_particles() == 0) continue;
    // The lowest particle and the fastest approach (relative to the surface, along its normal).
    Real lowest = std::numeric_limits<Real>::infinity();
    Vec3 n = Vec3::UnitY();
    Real approach = 0;
    for (int i = 0; i < model.num_particles(); ++i) {
      const Vec3 x = particle(state.x, i);
      const Vec3 ni = terrain.normal(x, state.t);
      const Real d = terrain.signed_distance(x, state.t);
      if (d < lowest) {
        lowest = d;
        n = ni;
      }
      approach = std::max(approach,
                          -(particle(state.v, i) - terrain.surface_velocity(x, state.t)).dot(ni));
    }
    const Real g = std::max<Real>(0, -model.gravity.dot(n));
    Real speed = std::sqrt(approach * approach + 2 * g * std::max<Real>(lowest, 0));
    // The surface's own approach (a rising elevator), sampled every millisecond.
    const Vec3 at = terrain.position(state.t);
    Real surface = 0;
    const long samples = std::min<long>(1000000, static_cast<long>((t_end - state.t) / 1e-3) + 1);
    for (long s = 0; s < samples; ++s) {
      const Real t = state.t + static_cast<Real>(s) * 1e-3;
      surface = std::max(surface, terrain.surface_velocity(at, t).dot(n));
    }
    speed += surface;
    if (!(speed * dt > 2 * c.epsilon)) continue;
    char text[640];
    std::snprintf(text, sizeof text,
                  "terrains[%zu]: the %s contact rules act within epsilon = %g m of the surface, "
                  "but at dt = %g s a particle arriving at up to %.3g m/s moves %.3g m per step: "
                  "it can cross that zone within one step and end about %.3g m below the surface "
                  "before they act. They were made for small steps (the report's dt = 0.001 s); "
                  "for large steps use the coulomb contact model "
                  "(terrains[%zu].contact.model = \"coulomb\"), which implicit_euler resolves "
                  "inside its solve",
                  k, std::string(contact_model_name(c.model)).c_str(), c.epsilon, dt, speed,
                  speed * dt, speed * dt - c.epsilon, k);
    out.emplace_back(text);
  }
  return out;
}

}  // namespace jelly
