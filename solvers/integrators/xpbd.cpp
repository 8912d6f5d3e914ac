#include <jelly/solvers/integrators/detail/xpbd.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/detail/position_contact.hpp>

namespace jelly {

Xpbd::Xpbd(XpbdOptions options)
    : options_(std::move(options)), contact_(std::make_unique<PositionContact>()) {
  options_.validate();
}

Xpbd::~Xpbd() = default;

Statistics Xpbd::statistics() const {
  Statistics s = Integrator::statistics();
  s["substeps"] = static_cast<double>(substeps_);
  s["sweeps"] = static_cast<double>(sweeps_);
  if (contact_in_step())
    s["contact_restitution_limited"] =
        static_cast<double>(contact_->counters().restitution_limited);
  return s;
}

void Xpbd::prepare(const Model& model, Real hs) {
  const Springs& s = model.springs;
  const bool same_model = mass_.size() == model.mass.size() && mass_ == model.mass && ks_ == s.ks &&
                          kd_ == s.kd && rest_ == s.rest_length && spring_a_ == s.a &&
                          spring_b_ == s.b && pinned_ == model.pins.particles;
  if (same_model && hs == hs_) return;
  if (!same_model) {  // once per model (allocates)
    mass_ = model.mass;
    ks_ = s.ks;
    kd_ = s.kd;
    rest_ = s.rest_length;
    spring_a_ = s.a;
    spring_b_ = s.b;
    rest_position_ = model.rest_position;
    pinned_ = model.pins.particles;
    inverse_mass_ = model.mass.cwiseInverse();
    for (int i : pinned_) inverse_mass_[i] = 0;  // constraints never move a pinned particle
    constraints_.resize(s.size());
    const int particles = model.num_particles();
    incidence_start_.assign(particles + 1, 0);
    for (int k = 0; k < s.size(); ++k) {
      ++incidence_start_[s.a[k] + 1];
      ++incidence_start_[s.b[k] + 1];
    }
    for (int i = 0; i < particles; ++i) incidence_start_[i + 1] += incidence_start_[i];
    incidence_.resize(incidence_start_[particles]);
    std::vector<int> fill(incidence_start_.begin(), incidence_start_.end() - 1);
    for (int k = 0; k < s.size(); ++k) {
      incidence_[fill[s.a[k]]++] = k;
      incidence_[fill[s.b[k]]++] = ~k;
    }
    impulse_.assign(3 * static_cast<size_t>(s.size()), 0.0);
    // The largest eigenvalue of sum n n^T over the springs at each particle (directions at
    // rest): at most their number, 32/3 inside a seed lattice. With w' = split_a wa + split_b wb
    // each spring's diagonal bounds its share of J W J^T (J W J^T <= diag(w')), so a Jacobi
    // sweep cannot overshoot (the summed corrections stay within the springs' own), at a third
    // of the splitting by count.
    split_.setZero(particles);
    for (int i = 0; i < particles; ++i) {
      Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
      for (int e = incidence_start_[i]; e < incidence_start_[i + 1]; ++e) {
        const int k = incidence_[e] >= 0 ? incidence_[e] : ~incidence_[e];
        Vec3 d = particle(model.rest_position, s.a[k]) - particle(model.rest_position, s.b[k]);
        const Real length = d.norm();
        if (!(length > 0)) {
          sum += Eigen::Matrix3d::Identity();  // no direction: bound it by 1 per spring
          continue;
        }
        d /= length;
        sum += d * d.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
      eigen.computeDirect(sum, Eigen::EigenvaluesOnly);
      split_[i] = std::max<Real>(eigen.eigenvalues().maxCoeff(), 1.0);
    }
    const int n = model.num_dofs();
    x_start_.setZero(n);
    f_.setZero(n);
    lambda_.setZero(s.size());
  }
  hs_ = hs;
  for (int k = 0; k < s.size(); ++k) {
    Constraint& c = constraints_[k];
    c.a = s.a[k];
    c.b = s.b[k];
    c.rest = s.rest_length[k];
    c.stiffness = s.ks[k] * hs * hs;
    c.damping = s.kd[k] * hs;
    // Jacobi: mass splitting, each spring at a particle sees its mass divided by the share
    // split_ of its springs (below).
    const bool jacobi = options_.sweep == XpbdSweep::kJacobi;
    const auto share = [&](int i) { return jacobi ? split_[i] : Real(1); };
    const Real w = share(c.a) * inverse_mass_[c.a] + share(c.b) * inverse_mass_[c.b];
    c.inverse_denominator = 1.0 / ((c.stiffness + c.damping) * w + 1);
  }
}

namespace {
// The unit direction n = (xa - xb) / |xa - xb| and the length of the spring a-b at positions px
// (the direction at rest for a collapsed spring); false when it has none. File-local so that the
// sweeps' calls (one per spring) are inlined: a member of the exported class was called through
// the PLT from within the library.
inline bool xpbd_spring_direction(const Real* px, const Real* rest_position, int a, int b,
                                  Real rest, Real n[3], Real& length) {
  const Real* xa = px + 3 * a;
  const Real* xb = px + 3 * b;
  const Real d[3] = {xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2]};
  length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (length >= kDegenerateLength * rest && length > 0) {
    const Real inv = 1.0 / length;
    for (int q = 0; q < 3; ++q) n[q] = d[q] * inv;
    return true;
  }
  // Collapsed: the direction at rest.
  const Real* ra = rest_position + 3 * a;
  const Real* rb = rest_position + 3 * b;
  for (int q = 0; q < 3; ++q) n[q] = ra[q] - rb[q];
  const Real r = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(r > 0)) return false;
  for (int q = 0; q < 3; ++q) n[q] /= r;
  return true;
}
}  // namespace

void Xpbd::sweep(VecX& x, int threads) {
  Real* px = x.data();
  const Real* p0 = x_start_.data();
  const Real* w = inverse_mass_.data();
  Real* lambda = lambda_.data();
  Real* impulse = impulse_.data();
  const Constraint* constraints = constraints_.data();
  const Real* rest = rest_position_.data();
  // Every spring's impulse from the same positions (each writes only its own entries) ...
  parallel::for_ranges(threads, static_cast<long>(constraints_.size()), [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const Constraint& c = constraints[k];
      const Real* xa = px + 3 * c.a;
      const Real* xb = px + 3 * c.b;
      Real* out = impulse + 3 * k;
      Real n[3];
      Real length = 0;
      if (!xpbd_spring_direction(px, rest, c.a, c.b, c.rest, n, length)) {
        out[0] = out[1] = out[2] = 0;
        continue;
      }
      const Real* a0 = p0 + 3 * c.a;
      const Real* b0 = p0 + 3 * c.b;
      // grad C . (x - x_start): the change of the spring's length rate over the substep.
      Real moved = 0;
      for (int q = 0; q < 3; ++q) moved += n[q] * ((xa[q] - a0[q]) - (xb[q] - b0[q]));
      const Real dl = (-c.stiffness * (length - c.rest) - lambda[k] - c.damping * moved) *
                      c.inverse_denominator;
      lambda[k] += dl;
      for (int q = 0; q < 3; ++q) out[q] = dl * n[q];
    }
  });
  // ... then each particle takes the sum of its springs' impulses, in the fixed order of its
  // incidence list: the same bits for any split between threads.
  const int* start = incidence_start_.data();
  const int* incidence = incidence_.data();
  const long particles = static_cast<long>(incidence_start_.size()) - 1;
  parallel::for_ranges(threads, particles, [&](long begin, long end) {
    for (long i = begin; i < end; ++i) {
      if (w[i] == 0) continue;
      Real sum[3] = {0, 0, 0};
      for (int e = start[i]; e < start[i + 1]; ++e) {
        const int k = incidence[e];
        const Real* p = impulse + 3 * static_cast<long>(k >= 0 ? k : ~k);
        if (k >= 0) {
          for (int q = 0; q < 3; ++q) sum[q] += p[q];
        } else {
          for (int q = 0; q < 3; ++q) sum[q] -= p[q];
        }
      }
      Real* xi = px + 3 * i;
      for (int q = 0; q < 3; ++q) xi[q] += w[i] * sum[q];
    }
  });
}

void Xpbd::sweep_in_order(VecX& x) {
  Real* px = x.data();
  const Real* p0 = x_start_.data();
  const Real* w = inverse_mass_.data();
  Real* lambda = lambda_.data();
  const int m = static_cast<int>(constraints_.size());
  for (int k = 0; k < m; ++k) {
    const Constraint& c = constraints_[k];
    Real* xa = px + 3 * c.a;
    Real* xb = px + 3 * c.b;
    Real n[3];
    Real length = 0;
    if (!xpbd_spring_direction(px, rest_position_.data(), c.a, c.b, c.rest, n, length)) continue;
    const Real* a0 = p0 + 3 * c.a;
    const Real* b0 = p0 + 3 * c.b;
    Real moved = 0;
    for (int q = 0; q < 3; ++q) moved += n[q] * ((xa[q] - a0[q]) - (xb[q] - b0[q]));
    const Real dl =
        (-c.stiffness * (length - c.rest) - lambda[k] - c.damping * moved) * c.inverse_denominator;
    lambda[k] += dl;
    const Real sa = w[c.a] * dl, sb = w[c.b] * dl;
    for (int q = 0; q < 3; ++q) {
      xa[q] += sa * n[q];
      xb[q] -= sb * n[q];
    }
  }
}

void Xpbd::sweep_anchors(const AnchorSprings& anchors, Real hs, VecX& x) {
  // Each anchor spring is the vector constraint C = x_p - target with compliance 1 / k and
  // damping c on the particle's own motion: the same update as a spring's, per coordinate.
  for (size_t k = 0; k < anchors.size(); ++k) {
    const AnchorSpring& a = anchors[k];
    const Real w = inverse_mass_[a.particle];
    const Real stiffness = a.stiffness * hs * hs, damping = a.damping * hs;
    const Real inverse_denominator = 1.0 / ((stiffness + damping) * w + 1);
    auto xp = particle(x, a.particle);
    const Vec3 dl = (-stiffness * (Vec3(xp) - a.target) - anchor_lambda_[k] -
                     damping * (Vec3(xp) - particle(x_start_, a.particle))) *
                    inverse_denominator;
    anchor_lambda_[k] += dl;
    xp += w * dl;
  }
}

void Xpbd::place_pins(const Pins& pins, Real t, VecX& x) const {
  for (int k = 0; k < pins.size(); ++k) particle(x, pins.particles[k]) = pins.position(k, t);
}

StepResult Xpbd::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Model& model = dynamics.model();
  const int substeps = options_.substeps;
  const Real hs = h / substeps;
  prepare(model, hs);
  const int n = model.num_particles();
  const Terrains* terrains = dynamics.terrains();
  terrains_seen_ = terrains != nullptr;
  const Real t_end = s.t + h;
  for (int sub = 0; sub < substeps; ++sub) {
    // External forces: gravity, the model's external and added forces and the seed model's
    // contact forces.
    for (int i = 0; i < n; ++i) particle(f_, i) = model.mass[i] * model.gravity;
    dynamics.add_applied_forces(s.t, s.x, s.v, f_);
    dynamics.contacts().add_forces(s.v, f_);
    const Real t1 = sub + 1 == substeps ? t_end : s.t + hs;
    contact_active_ = contact_in_step() && contact_->begin(model, *terrains, s, hs);
    x_start_ = s.x;
    for (int i = 0; i < n; ++i) {
      particle(s.v, i) += (hs * inverse_mass_[i]) * particle(f_, i);
      particle(s.x, i) += hs * particle(s.v, i);
    }
    place_pins(model.pins, t1, s.x);
    lambda_.setZero();
    const AnchorSprings* anchors = dynamics.anchors();
    if (anchors) anchor_lambda_.assign(anchors->size(), Vec3::Zero());
    // Contacts before each sweep, so that the springs carry their correction up the jelly
    // within the sweep, and after the last, so that the substep ends on the surfaces.
    for (int it = 0; it < options_.iterations; ++it) {
      if (contact_active_) contact_->project_with_friction(s.x);
      if (options_.sweep == XpbdSweep::kJacobi) {
        sweep(s.x, dynamics.threads());
      } else {
        sweep_in_order(s.x);
      }
      if (anchors) sweep_anchors(*anchors, hs, s.x);
      ++sweeps_;
    }
    if (contact_active_) contact_->project_with_friction(s.x);
    place_pins(model.pins, t1, s.x);
    s.v = (s.x - x_start_) / hs;
    s.t = t1;
    if (contact_active_) contact_->finish(model, s, dynamics.threads());
    ++substeps_;
  }
  if (!s.x.allFinite() || !s.v.allFinite())
    return StepResult::failure("xpbd: a position or velocity is not finite");
  StepResult result = StepResult::success();
  result.contact = {contact_in_step(), false, contact_active_ ? contact_->count() : 0};
  return result;
}

}  // namespace jelly
