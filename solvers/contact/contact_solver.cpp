#include <jelly/solvers/contact/detail/contact_solver.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>

namespace jelly {

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
    const TerrainContactModel& contact_model = terrain_contact_model(c.model);
    if (scope == Scope::kUnsolvedOnly && contact_model.constrains_solves()) continue;
    const AfterStepContact step{model, *terrain, c, before, state, h};
    int parts_used = 1;
    parallel::run(team, [&](int part, int parts) {
      if (part == 0) parts_used = parts;
      const parallel::Range r = parallel::split(np, part, parts);
      std::vector<CarriedContact>& carried = part_seed_[part];
      carried.clear();
      part_count_[part] = contact_model.resolve_after_step(step, static_cast<int>(r.begin),
                                                           static_cast<int>(r.end), carried);
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
    const TerrainContactModel& contact_model = terrain_contact_model(*terrain);
    if (contact_model.acts_in_evaluation())
      contact_model.apply_in_evaluation(model, *terrain, t, x, v, f);
  }
}

bool ContactSolver::has_in_evaluation_contact(const Terrains& terrains) {
  return std::any_of(terrains.begin(), terrains.end(), [](const auto& terrain) {
    return terrain_contact_model(*terrain).acts_in_evaluation();
  });
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
