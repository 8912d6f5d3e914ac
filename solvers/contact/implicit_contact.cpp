#include <jelly/solvers/contact/detail/implicit_contact.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/contact/detail/friction.hpp>
#include <jelly/solvers/contact/detail/thickness.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>

namespace jelly {

namespace {

using friction::kStickViscosity;
using friction::tangential;

using Mat3 = Eigen::Matrix3d;

// A particle this far below a surface at the end of a solve becomes a contact; a contact whose
// explicit prediction ends at most this far above its surface stays one.
constexpr Real kPenetrationTolerance = 1e-9;  // m
constexpr Real kTouchTolerance = 1e-6;        // m
// A prescribed normal velocity above -this is "not moving towards the surface" (round-off).
constexpr Real kTouchSpeed = 1e-9;  // m/s

// The three columns of particle j in a full-storage matrix of dense 3x3 blocks: entry
// (3 i + r, 3 j + q) of the block in slot k (row particle i) is values[start + q stride + 3 k + r].
struct BlockColumn {
  int start, stride;
  int blocks() const { return stride / 3; }
};

BlockColumn block_column(const SparseMatrix& a, int j) {
  const int* outer = a.outerIndexPtr();
  return {outer[3 * j], outer[3 * j + 1] - outer[3 * j]};
}

int row_particle(const SparseMatrix& a, const BlockColumn& col, int k) {
  return a.innerIndexPtr()[col.start + 3 * k] / 3;
}

// The slot of row particle i in column particle j (the pattern is symmetric, so it exists).
int slot_of(const SparseMatrix& a, const BlockColumn& col, int i) {
  const int* rows = a.innerIndexPtr() + col.start;
  return static_cast<int>(std::lower_bound(rows, rows + col.stride, 3 * i) - rows) / 3;
}

Mat3 read_block(const Real* values, const BlockColumn& col, int k) {
  Mat3 b;
  for (int q = 0; q < 3; ++q)
    for (int r = 0; r < 3; ++r) b(r, q) = values[col.start + q * col.stride + 3 * k + r];
  return b;
}

void write_block(Real* values, const BlockColumn& col, int k, const Mat3& b) {
  for (int q = 0; q < 3; ++q)
    for (int r = 0; r < 3; ++r) values[col.start + q * col.stride + 3 * k + r] = b(r, q);
}

// Whether the terrain's contact model is a constraint of the solve (coulomb).
bool uses_coulomb(const Terrain& terrain) {
  return terrain_contact_model(terrain).constrains_solves();
}

}  // namespace

Mat3 ImplicitContact::free_projector(const Contact& c) {
  if (c.pinned || c.mode == Mode::kStick) return Mat3::Zero();
  return Mat3::Identity() - c.normal * c.normal.transpose();
}

Mat3 ImplicitContact::filtered_diagonal(const Contact& c, const Mat3& d) {
  const Mat3 sc = free_projector(c);
  const Real viscosity = c.mode == Mode::kSlide && !c.pinned ? c.viscosity : 0.0;
  return sc * d * sc + viscosity * sc + Mat3::Identity() - sc;
}

Vec3 ImplicitContact::prescribed_change(const Contact& c) const {
  const Vec3 v0 = particle(v0_, c.particle);
  if (c.pinned) return c.target_velocity - v0;
  if (c.mode == Mode::kStick)
    return tangential(c.surface_velocity, c.normal) + c.target_normal * c.normal - v0;
  return (c.target_normal - v0.dot(c.normal)) * c.normal;
}

void ImplicitContact::subtract_sliding_friction(const Contact& c, VecX& rhs) const {
  if (c.pinned || c.mode != Mode::kSlide) return;
  const Vec3 v0 = particle(v0_, c.particle);
  particle(rhs, c.particle) -= c.viscosity * tangential(v0 - c.surface_velocity, c.normal);
}

int ImplicitContact::penetrated_terrain(const Terrains& terrains, const Vec3& p, Real gap,
                                        Real tolerance) const {
  int best = -1;
  Real deepest = -tolerance;
  for (int k = 0; k < static_cast<int>(terrains.size()); ++k) {
    const Terrain& terrain = *terrains[k];
    if (!uses_coulomb(terrain) || !terrain.can_contact(p, t1_)) continue;
    const Real d = terrain.signed_distance(p, t1_) - gap;
    if (d < deepest) {
      deepest = d;
      best = k;
    }
  }
  return best;
}

Real ImplicitContact::bounce_speed(const Contact& c, const Terrains& terrains) {
  if (c.pinned) return 0;
  const ContactParams& params = terrains[c.terrain]->contact();
  return c.approach > params.resting_speed ? params.restitution * c.approach : 0.0;
}

ImplicitContact::Contact ImplicitContact::make_contact(const Terrains& terrains, int i, int k,
                                                       const Vec3& v1, Real mass) const {
  const Terrain& terrain = *terrains[k];
  const Vec3 x0 = particle(x0_, i);
  Contact c;
  c.particle = i;
  c.terrain = k;
  c.normal = terrain.normal(x0, t1_);
  c.surface_velocity = terrain.surface_velocity(x0, t1_);
  c.target_normal = -(terrain.signed_distance(x0, t1_) - gap_[i]) / h_;
  c.approach = -(particle(v0_, i) - c.surface_velocity).dot(c.normal);
  // Stick or slide as a lone particle would: the normal velocity change dv_n the contact needs
  // bounds the friction impulse (mu_s m dv_n for sticking, mu m dv_n sliding).
  const ContactParams& params = terrain.contact();
  const Vec3 w = v1 - c.surface_velocity;
  const Real dvn = std::max(c.target_normal - v1.dot(c.normal), 0.0);
  const Vec3 wt = tangential(w, c.normal);
  const Real speed = wt.norm();
  if (speed > params.static_friction * dvn) {  // (mass speed > mu m dv_n: c > 0)
    c.mode = Mode::kSlide;
    c.viscosity = params.friction * mass * dvn / (speed - params.friction * dvn);
  }
  return c;
}

void ImplicitContact::index_contacts() {
  std::fill(slot_.begin(), slot_.end(), -1);
  for (int ci = 0; ci < static_cast<int>(contacts_.size()); ++ci)
    slot_[contacts_[ci].particle] = ci;
}

template <class Position>
void ImplicitContact::find_penetrating(const Terrains& terrains, Position&& position,
                                       Real tolerance) {
  penetrating_.resize(slot_.size());
  // (Each particle costs a few virtual calls per terrain: worth a thread from about a thousand.)
  parallel::for_ranges(
      threads_, static_cast<long>(slot_.size()),
      [&](long begin, long end) {
        for (long i = begin; i < end; ++i) {
          penetrating_[i] =
              slot_[i] >= 0
                  ? -1
                  : penetrated_terrain(terrains, position(static_cast<int>(i)), gap_[i], tolerance);
        }
      },
      parallel::kMinParticlesPerThread);
}

void ImplicitContact::renumber_terrains(const Terrains& terrains) {
  const auto seen = [&](const Terrain* t) {
    return std::find(last_terrains_.begin(), last_terrains_.end(), t) != last_terrains_.end();
  };
  terrain_index_.assign(last_terrains_.size(), -1);
  for (size_t k = 0; k < last_terrains_.size(); ++k) {
    const auto at = std::find_if(terrains.begin(), terrains.end(),
                                 [&](const auto& t) { return t.get() == last_terrains_[k]; });
    if (at != terrains.end()) {
      terrain_index_[k] = static_cast<int>(at - terrains.begin());
    } else if (k < terrains.size() && !seen(terrains[k].get())) {
      terrain_index_[k] = static_cast<int>(k);  // replaced in place
    }
  }
  last_terrains_.clear();
  for (const auto& t : terrains) last_terrains_.push_back(t.get());
}

bool ImplicitContact::begin_step(const Model& model, const Terrains& terrains, const State& s0,
                                 const VecX& f, Real h, int threads) {
  threads_ = threads;
  thickness::fill(model, gap_);
  const bool any = std::any_of(terrains.begin(), terrains.end(),
                               [](const auto& terrain) { return uses_coulomb(*terrain); });
  projected_ = 0;
  pinned_ = 0;
  if (!any && model.pins.empty()) {
    contacts_.clear();
    return false;
  }
  const int np = model.num_particles();
  t1_ = s0.t + h;
  h_ = h;
  x0_ = s0.x;
  v0_ = s0.v;
  model_ = &model;
  slot_.resize(np);
  // The explicit prediction x0 + h v1, v1 = v0 + h f / m: last step's contacts (unless let go)
  // that it keeps on their surface, and the particles it carries into a terrain.
  std::fill(slot_.begin(), slot_.end(), -1);
  renumber_terrains(terrains);
  for (int ci = 0; ci < static_cast<int>(contacts_.size()); ++ci) {
    Contact& old = contacts_[ci];
    if (old.pinned || old.release || old.particle >= np) continue;
    if (!terrain_index_.empty()) {
      old.terrain =
          old.terrain < static_cast<int>(terrain_index_.size()) ? terrain_index_[old.terrain] : -1;
    }
    if (old.terrain < 0 || old.terrain >= static_cast<int>(terrains.size())) continue;
    slot_[old.particle] = ci;
  }
  next_.clear();
  // Pins first: their velocity at t1 is their path's.
  std::vector<char>& is_pinned = pinned_mask_;
  is_pinned.assign(np, 0);
  for (int k = 0; k < model.pins.size(); ++k) {
    Contact c;
    c.particle = model.pins.particles[k];
    c.terrain = -1;
    c.pinned = true;
    c.target_velocity = model.pins.sample(k, t1_).velocity;
    next_.push_back(c);
    is_pinned[c.particle] = 1;
  }
  pinned_ = static_cast<int>(next_.size());
  const auto predicted_velocity = [&](int i) {
    return Vec3(particle(v0_, i) + (h / model.mass[i]) * particle(f, i));
  };
  find_penetrating(
      terrains, [&](int i) { return Vec3(particle(x0_, i) + h * predicted_velocity(i)); }, 0);
  for (int i = 0; i < np; ++i) {
    // (A free particle that the prediction keeps above every terrain has nothing to add.)
    if (is_pinned[i] || (slot_[i] < 0 && penetrating_[i] < 0)) continue;
    const Vec3 v1 = predicted_velocity(i);
    const Vec3 predicted = particle(x0_, i) + h * v1;
    if (slot_[i] >= 0) {
      const Contact& old = contacts_[slot_[i]];
      const Terrain& terrain = *terrains[old.terrain];
      if (uses_coulomb(terrain) && terrain.can_contact(predicted, t1_) &&
          terrain.signed_distance(predicted, t1_) - gap_[i] <= kTouchTolerance) {
        Contact c = make_contact(terrains, i, old.terrain, v1, model.mass[i]);
        c.mode = old.mode;
        c.viscosity = old.viscosity;
        next_.push_back(c);
        continue;
      }
    }
    // A last contact that let go may still be predicted below its surface.
    const int k =
        slot_[i] >= 0 ? penetrated_terrain(terrains, predicted, gap_[i], 0) : penetrating_[i];
    if (k >= 0) next_.push_back(make_contact(terrains, i, k, v1, model.mass[i]));
  }
  contacts_.swap(next_);
  index_contacts();
  return true;
}

void ImplicitContact::constrain(SparseMatrix& a, const VecX& b, bool prescribe, VecX& rhs, VecX& z,
                                VecX& guess) {
  Real* values = a.valuePtr();
  saved_.clear();
  saved_at_.clear();
  for (const Contact& c : contacts_) {
    const BlockColumn col = block_column(a, c.particle);
    saved_at_.push_back(static_cast<int>(saved_.size()));
    saved_.insert(saved_.end(), values + col.start, values + col.start + 3 * col.stride);
  }
  // rhs = b - C w0 - A z, with A's original columns.
  rhs = b;
  z.setZero();
  for (int ci = 0; ci < static_cast<int>(contacts_.size()); ++ci) {
    const Contact& c = contacts_[ci];
    if (!prescribe) continue;
    const Vec3 dz = prescribed_change(c);
    subtract_sliding_friction(c, rhs);
    particle(z, c.particle) = dz;
    const BlockColumn col = block_column(a, c.particle);
    const Real* orig = saved_.data() + saved_at_[ci];
    for (int k = 0; k < col.blocks(); ++k) {
      const int i = row_particle(a, col, k);
      for (int r = 0; r < 3; ++r) {
        Real s = 0;
        for (int q = 0; q < 3; ++q) s += orig[q * col.stride + 3 * k + r] * dz[q];
        rhs[3 * i + r] -= s;
      }
    }
  }
  // A -> S A S + I - S, block by block (idempotent where two constrained particles meet).
  for (const Contact& c : contacts_) {
    const Mat3 sc = free_projector(c);
    const BlockColumn col = block_column(a, c.particle);
    for (int k = 0; k < col.blocks(); ++k) {
      const int i = row_particle(a, col, k);
      const Mat3 block = read_block(values, col, k);
      if (i == c.particle) {  // sliding: the friction viscosity on the tangent plane (sc)
        write_block(values, col, k, filtered_diagonal(c, block));
        continue;
      }
      const Mat3 filtered =
          slot_[i] >= 0 ? Mat3(free_projector(contacts_[slot_[i]]) * block * sc) : Mat3(block * sc);
      write_block(values, col, k, filtered);
      const BlockColumn row = block_column(a, i);
      write_block(values, row, slot_of(a, row, c.particle), filtered.transpose());
    }
  }
  project(rhs);
  project(guess);
}

void ImplicitContact::unconstrain(SparseMatrix& a) const {
  Real* values = a.valuePtr();
  for (int ci = 0; ci < static_cast<int>(contacts_.size()); ++ci) {
    const int j = contacts_[ci].particle;
    const BlockColumn col = block_column(a, j);
    const Real* orig = saved_.data() + saved_at_[ci];
    std::copy(orig, orig + 3 * col.stride, values + col.start);
    const BlockColumn saved{0, col.stride};
    for (int k = 0; k < col.blocks(); ++k) {
      const int i = row_particle(a, col, k);
      if (i == j) continue;
      const BlockColumn row = block_column(a, i);
      write_block(values, row, slot_of(a, row, j), read_block(orig, saved, k).transpose());
    }
  }
}

bool ImplicitContact::constrain_rhs(const VecX& b, bool prescribe, const VecX* a_z, VecX& rhs,
                                    VecX& z, VecX& guess) {
  if (a_z == nullptr) {
    z.setZero();
    bool any = false;
    if (!prescribe) return false;
    for (const Contact& c : contacts_) {
      const Vec3 dz = prescribed_change(c);
      particle(z, c.particle) = dz;
      any = any || dz != Vec3::Zero();
    }
    return any;
  }
  // rhs = S (b - C w0 - A z).
  rhs = b - *a_z;
  if (prescribe) {
    for (const Contact& c : contacts_) subtract_sliding_friction(c, rhs);
  }
  project(rhs);
  project(guess);
  return true;
}

ProductFilter ImplicitContact::product_filter() {
  projectors_.resize(9 * contacts_.size());
  viscosities_.resize(contacts_.size());
  for (size_t k = 0; k < contacts_.size(); ++k) {
    const Contact& c = contacts_[k];
    const Mat3 s = free_projector(c);
    std::copy(s.data(), s.data() + 9, projectors_.data() + 9 * k);
    viscosities_[k] = c.mode == Mode::kSlide && !c.pinned ? c.viscosity : 0.0;
  }
  return ProductFilter{slot_.data(), projectors_.data(), viscosities_.data()};
}

bool ImplicitContact::filter_diagonal_block(int i, Real block[9]) const {
  if (i < 0 || i >= static_cast<int>(slot_.size()) || slot_[i] < 0) return false;
  Mat3 d;
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) d(r, q) = block[3 * r + q];
  const Mat3 f = filtered_diagonal(contacts_[slot_[i]], d);
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) block[3 * r + q] = f(r, q);
  return true;
}

void ImplicitContact::project(VecX& w) const {
  for (const Contact& c : contacts_)
    particle(w, c.particle) = free_projector(c) * particle(w, c.particle);
}

namespace {
constexpr size_t kSavedPerContact = 5;
}

void ImplicitContact::save(std::vector<Real>& out) const {
  for (const Contact& c : contacts_) {
    if (c.pinned) continue;  // rebuilt from the model at every step
    out.push_back(c.particle);
    out.push_back(c.terrain);
    out.push_back(c.mode == Mode::kSlide ? 1 : 0);
    out.push_back(c.viscosity);
    out.push_back(c.release ? 1 : 0);
  }
}

void ImplicitContact::restore(const Real* data, size_t size) {
  require(size % kSavedPerContact == 0, "integrator state (contacts)", size,
          "5 numbers per contact");
  contacts_.clear();
  last_terrains_.clear();  // the saved indices are the current terrains'
  for (size_t i = 0; i < size; i += kSavedPerContact) {
    Contact c;
    constexpr Real kMaxIndex = std::numeric_limits<int>::max();
    require(data[i] >= 0 && data[i] == std::floor(data[i]) && data[i] <= kMaxIndex &&
                data[i + 1] >= 0 && data[i + 1] == std::floor(data[i + 1]) &&
                data[i + 1] <= kMaxIndex,
            "integrator state (contact particle)", data[i], "a particle and a terrain index");
    require(std::isfinite(data[i + 3]) && data[i + 3] >= 0, "integrator state (contact viscosity)",
            data[i + 3], "a finite value >= 0");
    c.particle = static_cast<int>(data[i]);
    c.terrain = static_cast<int>(data[i + 1]);
    c.mode = data[i + 2] != 0 ? Mode::kSlide : Mode::kStick;
    c.viscosity = data[i + 3];
    c.release = data[i + 4] != 0;
    contacts_.push_back(c);
  }
}

void ImplicitContact::subtract_friction(const VecX& v1, VecX& w) const {
  for (const Contact& c : contacts_) {
    if (c.pinned || c.mode != Mode::kSlide) continue;
    particle(w, c.particle) +=
        c.viscosity * tangential(particle(v1, c.particle) - c.surface_velocity, c.normal);
  }
}

bool ImplicitContact::update(const Terrains& terrains, const VecX& b, const VecX& dv, bool commit,
                             SparseMatrix& a) {
  // p = (A dv - b)_c from the original column (A is symmetric).
  return update_impl(
      terrains, dv, commit, false,
      [&](int ci, const Contact& c) {
        const BlockColumn col = block_column(a, c.particle);
        const Real* orig = saved_.data() + saved_at_[ci];
        Vec3 p = -particle(b, c.particle);
        for (int k = 0; k < col.blocks(); ++k) {
          const int i = row_particle(a, col, k);
          for (int q = 0; q < 3; ++q)
            for (int r = 0; r < 3; ++r) p[q] += orig[q * col.stride + 3 * k + r] * dv[3 * i + r];
        }
        return p;
      },
      [&] { unconstrain(a); });
}

bool ImplicitContact::update_from_product(const Terrains& terrains, const VecX& b, const VecX& dv,
                                          bool commit, const VecX& a_dv, bool screening) {
  return update_impl(
      terrains, dv, commit, screening,
      [&](int, const Contact& c) {
        return Vec3(particle(a_dv, c.particle) - particle(b, c.particle));
      },
      [] {});
}

template <class Impulse, class Unconstrain>
bool ImplicitContact::update_impl(const Terrains& terrains, const VecX& dv, bool commit,
                                  bool screening, Impulse&& impulse,
                                  Unconstrain&& unconstrain_matrix) {
  bool changed = false;
  next_.clear();
  for (int ci = 0; ci < static_cast<int>(contacts_.size()); ++ci) {
    Contact c = contacts_[ci];
    if (c.pinned) {  // a pin holds whatever force it takes
      next_.push_back(c);
      continue;
    }
    // (Sliding friction is tangential and only p_n of a sliding contact is used.)
    const Vec3 p = impulse(ci, c);
    const Vec3& n = c.normal;
    const Real pn = p.dot(n);
    c.normal_impulse = pn;
    c.impulse = p;
    c.release = false;  // decided again by this solve
    if (pn < 0) {       // the surface would have to pull: let go
      // A particle that does not move towards its surface (n.v1 >= 0 prescribed) is pulled
      // without work: it is held for this step and let go at the next (no solve again).
      // Otherwise the pull would do work: solve again without it.
      if (c.target_normal >= -kTouchSpeed) {
        c.release = true;
        next_.push_back(c);
      } else {
        changed = true;
      }
      continue;
    }
    const ContactParams& params = terrains[c.terrain]->contact();
    if (c.mode == Mode::kStick) {
      const Vec3 pt = p - pn * n;
      const Real pt_norm = pt.norm();
      if (pt_norm > params.static_friction * pn) {  // outside the friction cone: slide
        c.mode = Mode::kSlide;
        // Alone it would slide with momentum |p_t|; friction mu p_n = c |p_t| / (m + c).
        const Real force = params.friction * pn;
        c.viscosity = force * model_->mass[c.particle] / (pt_norm - force);
      }
    } else {
      const Vec3 w = particle(v0_, c.particle) + particle(dv, c.particle) - c.surface_velocity;
      const Real speed = tangential(w, n).norm();
      // The viscosity that gives friction mu p_n at this speed, for the next solve (or step):
      // a change of it alone is no reason to solve again, the friction stays dissipative.
      const Real m = model_->mass[c.particle];
      const Real viscosity = params.friction * pn / std::max(speed, 1e-300);
      if (viscosity >= kStickViscosity * m) {  // friction has all but stopped it: stick
        c.mode = Mode::kStick;
        c.viscosity = 0;
      } else {
        c.viscosity = viscosity;
      }
    }
    next_.push_back(c);
  }
  // Free particles the solve carried into a terrain.
  find_penetrating(
      terrains,
      [&](int i) { return Vec3(particle(x0_, i) + h_ * (particle(v0_, i) + particle(dv, i))); },
      kPenetrationTolerance);
  for (int i = 0; i < static_cast<int>(slot_.size()); ++i) {
    const int k = penetrating_[i];
    if (k >= 0) {
      const Vec3 v1 = particle(v0_, i) + particle(dv, i);
      next_.push_back(make_contact(terrains, i, k, v1, model_->mass[i]));
      changed = true;
    }
  }
  if (!changed) {  // same particles in the same order: keep the new impulses and friction
    // (Screening: the finished solve decides them. Taking them from the loose solve as well
    // would update the friction once more per step than without screening, which moved the
    // run by millimetres: docs/implicit.md, "Screening the contacts' set".)
    if (!screening) contacts_.swap(next_);
  } else if (commit) {
    unconstrain_matrix();
    contacts_.swap(next_);
    index_contacts();
    ++counters_.extra_solves;
  } else {  // the solve's set stays; its kept contacts (first in next_, in order) update
    ++counters_.not_converged;
    size_t j = 0;
    for (Contact& c : contacts_) {
      if (j < next_.size() && next_[j].particle == c.particle) c = next_[j++];
    }
  }
  return changed;
}

void ImplicitContact::finish(const Model& model, const Terrains& terrains, State& s1, int threads) {
  // Particles left below a surface (the active set was still changing when the solves ran out):
  // onto the surface, without inward velocity.
  projected_ = 0;
  threads_ = threads;
  find_penetrating(
      terrains, [&](int i) { return Vec3(particle(s1.x, i)); }, kPenetrationTolerance);
  for (int i = 0; i < model.num_particles(); ++i) {
    const int k = penetrating_[i];
    if (k < 0) continue;
    auto x = particle(s1.x, i);
    const Terrain& terrain = *terrains[k];
    const Vec3 n = terrain.normal(x, t1_);
    const Vec3 u = terrain.surface_velocity(x, t1_);
    x -= (terrain.signed_distance(x, t1_) - gap_[i]) * n;
    auto v = particle(s1.v, i);
    const Real vn = (v - u).dot(n);
    if (vn < 0) v -= vn * n;
    ++projected_;
  }
  // Contacts end at rest on their surface in the normal direction.
  for (const Contact& c : contacts_) {
    if (c.pinned) continue;
    auto v = particle(s1.v, c.particle);
    v -= (v - c.surface_velocity).dot(c.normal) * c.normal;
  }
  // Restitution for the particles that hit their surface, within the energy the step lost.
  bounces_.clear();
  for (const Contact& c : contacts_) {
    const Real bounce = bounce_speed(c, terrains);  // 0 for pins
    if (bounce > 0) bounces_.push_back({c.particle, c.normal, c.surface_velocity, bounce});
  }
  if (add_bounded_bounces(model, x0_, v0_, t1_ - h_, s1, bounces_, threads) < 1)
    ++counters_.restitution_limited;
}

}  // namespace jelly
