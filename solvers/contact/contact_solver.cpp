#include <jelly/solvers/contact/contact_solver.hpp>

#include <cmath>

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

// Seed model (report 1.2 / 1.3): within epsilon and approaching, the normal velocity u1 becomes
// (m1 u1 + m2 u2 + m2 e (u2 - u1)) / (m1 + m2), u2 the surface's; a fixed plane (m2 infinite)
// gives u2 + e (u2 - u1) = -e u1. The tangential velocity is kept.
bool resolve_seed(const Terrain& terrain, const ContactParams& c, Real m1, Real t,
                  Eigen::Ref<const Vec3> x, Eigen::Ref<Vec3> v, Vec3& normal) {
  if (terrain.signed_distance(x, t) >= c.epsilon || !terrain.can_contact(x, t)) return false;
  const Vec3 n = terrain.normal(x, t);
  const Vec3 u = terrain.surface_velocity(x, t);
  if ((v - u).dot(n) >= 0) return false;
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

// Particles per thread below which another thread costs more than it saves.
constexpr long kMinParticlesPerThread = 1024;

}  // namespace

void ContactSolver::resolve(const Model& model, const Terrains& terrains, const State& before,
                            State& state, Real h, Scope scope, int threads) {
  seed_contacts_.clear();
  contact_count_ = 0;
  const int np = model.num_particles();
  const int team = parallel::team_size(threads, np, kMinParticlesPerThread);
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
        if (c.model == ContactModel::kCoulomb) {
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
  for (const SeedContact& c : seed_contacts_) {
    auto fi = particle(f, c.particle);
    const Real fn = fi.dot(c.normal);
    if (fn >= 0) continue;
    const Vec3 vi = particle(v, c.particle);
    const Vec3 vt = vi - vi.dot(c.normal) * c.normal;
    // Contact force -(f.n) n cancels the push; friction -mu N v_t with N = -(f.n).
    fi += -fn * c.normal + c.friction * fn * vt;
  }
}

void ContactSolver::clear() {
  seed_contacts_.clear();
  contact_count_ = 0;
}

void ContactSolver::restore(std::vector<SeedContact> seed_contacts, int contact_count) {
  seed_contacts_ = std::move(seed_contacts);
  contact_count_ = contact_count;
}

}  // namespace jelly
