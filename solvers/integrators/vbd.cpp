#include <jelly/solvers/integrators/detail/vbd.hpp>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/detail/thickness.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

namespace {

// Below this many particles of one colour, a second thread is not worth waking (each particle's
// update walks its 20-40 springs).
constexpr long kMinVbdParticlesPerThread = 128;

}  // namespace

Vbd::Vbd(VbdOptions options) : options_(std::move(options)) { options_.validate(); }

Statistics Vbd::statistics() const {
  Statistics s = Integrator::statistics();
  s["sweeps"] = static_cast<double>(sweeps_);
  s["colours"] = static_cast<double>(std::max(0, graph_.colours()));
  return s;
}

void Vbd::prepare(const Model& model) {
  const int n = model.num_particles();
  const bool same = static_cast<int>(graph_.spring_start.size()) == n + 1 &&
                    spring_a_ == model.springs.a && spring_b_ == model.springs.b;
  if (!same) {  // once per topology (allocates)
    graph_ = colour_vertices(n, model.springs);
    spring_a_ = model.springs.a;
    spring_b_ = model.springs.b;
    pinned_.assign(n, 0);
    anchor_first_.assign(n, -1);
  }
  // The springs' coefficients in the graph's order (they may change between steps).
  const size_t ends = graph_.spring.size();
  edge_rest_.resize(ends);
  edge_ks_.resize(ends);
  edge_kd_.resize(ends);
  for (size_t e = 0; e < ends; ++e) {
    const int k = graph_.spring[e];
    edge_rest_[e] = model.springs.rest_length[k];
    edge_ks_[e] = model.springs.ks[k];
    edge_kd_[e] = model.springs.kd[k];
  }
  std::fill(pinned_.begin(), pinned_.end(), 0);
  for (int i : model.pins.particles) pinned_[i] = 1;
}

Vec3 Vbd::update_particle(const Model& model, const AnchorSprings* anchors, Real h, Real t1, int i,
                          const VecX& x) const {
  const Springs& s = model.springs;
  const Real inv_h = 1.0 / h;
  const Vec3 xi(particle(x, i));
  const Vec3 moved_i = xi - Vec3(particle(x0_, i));  // h v_i at the iterate
  // The block of G at x_i: gradient -f (f the force on i) and Hessian H.
  const Real inertia = model.mass[i] * inv_h * inv_h;
  Vec3 f = -inertia * (xi - Vec3(particle(y_, i)));
  // H = diag I + sum of c u u^T over the springs, accumulated as 6 numbers (symmetric).
  Real diag = inertia, h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0;
  // The springs' elastic part alone (ks u u^T + clamped transverse term), for Rayleigh damping.
  Real e_diag = 0, e00 = 0, e01 = 0, e02 = 0, e11 = 0, e12 = 0, e22 = 0;
  const bool rayleigh = options_.damping > 0;
  const Real* px = x.data();
  const Real* p0 = x0_.data();
  for (int e = graph_.spring_start[i]; e < graph_.spring_start[i + 1]; ++e) {
    const int j = graph_.other[e];
    const Real* xj = px + 3 * j;
    const Real d0 = xi[0] - xj[0], d1 = xi[1] - xj[1], d2 = xi[2] - xj[2];
    const Real length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    const Real rest = edge_rest_[e];
    Real u0, u1, u2;
    Real inv_length = 0;  // 0 for a collapsed spring: no transverse terms
    if (length >= kDegenerateLength * rest && length > 0) {
      inv_length = 1.0 / length;
      u0 = d0 * inv_length;
      u1 = d1 * inv_length;
      u2 = d2 * inv_length;
    } else {  // collapsed: the direction at rest (i's end minus j's), as xpbd
      const int k = graph_.spring[e];
      const Real sign = s.a[k] == i ? 1 : -1;
      const Vec3 r = sign * (Vec3(particle(model.rest_position, s.a[k])) -
                             Vec3(particle(model.rest_position, s.b[k])));
      const Real r_length = r.norm();
      if (!(r_length > 0)) continue;
      u0 = r[0] / r_length;
      u1 = r[1] / r_length;
      u2 = r[2] / r_length;
    }
    // Spring force -ks (L - l0) u and damper force -kd ((v_i - v_j) . u) u, with the
    // velocities of the step's backward-Euler v = (x - x^t) / h.
    const Real* x0j = p0 + 3 * j;
    const Real rate = ((moved_i[0] - (xj[0] - x0j[0])) * u0 + (moved_i[1] - (xj[1] - x0j[1])) * u1 +
                       (moved_i[2] - (xj[2] - x0j[2])) * u2) *
                      inv_h;
    const Real ks = edge_ks_[e], kd = edge_kd_[e];
    const Real magnitude = ks * (length - rest) + kd * rate;
    f[0] -= magnitude * u0;
    f[1] -= magnitude * u1;
    f[2] -= magnitude * u2;
    // -df_i/dx_i = ks u u^T + (ks (1 - l0/L) + kd c/L) P (P = I - u u^T) + (kd / h) u u^T,
    // each transverse term clamped at >= 0 (Choi and Ko 2002, implicit_euler's default):
    // = b I + (a - b) u u^T with a = ks + kd / h, b the clamped transverse terms.
    const Real transverse_elastic =
        inv_length > 0 ? std::max<Real>(0, ks * (1 - rest * inv_length)) : 0;
    const Real transverse_damper = std::max<Real>(0, kd * rate * inv_length);
    const Real b = transverse_elastic + transverse_damper;
    const Real c = ks + kd * inv_h - b;
    diag += b;
    h00 += c * u0 * u0;
    h01 += c * u0 * u1;
    h02 += c * u0 * u2;
    h11 += c * u1 * u1;
    h12 += c * u1 * u2;
    h22 += c * u2 * u2;
    if (rayleigh) {
      const Real ce = ks - transverse_elastic;
      e_diag += transverse_elastic;
      e00 += ce * u0 * u0;
      e01 += ce * u0 * u1;
      e02 += ce * u0 * u2;
      e11 += ce * u1 * u1;
      e12 += ce * u1 * u2;
      e22 += ce * u2 * u2;
    }
  }
  Eigen::Matrix3d hess;
  hess << diag + h00, h01, h02, h01, diag + h11, h12, h02, h12, diag + h22;
  if (rayleigh) {  // Chen et al. 2024, eq. 14: -(damping / h) H_elastic (x_i - x_i^t)
    Eigen::Matrix3d elastic;
    elastic << e_diag + e00, e01, e02, e01, e_diag + e11, e12, e02, e12, e_diag + e22;
    const Real c = options_.damping * inv_h;
    f -= c * (elastic * moved_i);
    hess += c * elastic;
  }
  if (anchors) {
    for (int a = anchor_first_[i]; a >= 0; a = anchor_next_[a]) {
      const AnchorSpring& spring = (*anchors)[a];
      f -= spring.stiffness * (xi - spring.target) + spring.damping * inv_h * moved_i;
      hess.diagonal().array() += spring.stiffness + spring.damping * inv_h;
    }
  }
  // Penalty contact: E = k d^2 / 2 below a coulomb surface at t1 (d < 0; d less the particle's
  // thickness), force -k d n.
  for (const Terrain* terrain : penalty_terrains_) {
    if (!terrain->can_contact(xi, t1)) continue;
    const Real d = terrain->signed_distance(xi, t1) - gap_[i];
    if (d >= 0) continue;
    const Vec3 normal = terrain->normal(xi, t1);
    const Real k = options_.contact_hardness * inertia;
    f -= k * d * normal;
    hess += k * normal * normal.transpose();
  }
  // H is symmetric positive definite (inertia + clamped, positive semidefinite terms).
  const Eigen::LLT<Eigen::Matrix3d> llt(hess);
  return xi + llt.solve(f);
}

void Vbd::sweep(const Model& model, const AnchorSprings* anchors, Real h, Real t1, VecX& x,
                int threads) {
  const int team = parallel::team_size(threads, graph_.largest_colour(), kMinVbdParticlesPerThread);
  // One team for the sweep, colour after colour, a barrier between colours. Within a colour each
  // particle reads only particles of other colours, or, in a coupled colour, the positions from
  // before the colour (its new positions go to next_ first): the result is that of any order.
  parallel::run(team, [&](int part, int parts) {
    for (int c = 0; c < graph_.colours(); ++c) {
      const long begin = graph_.colour_start[c], count = graph_.colour_start[c + 1] - begin;
      const parallel::Range r = parallel::split(count, part, parts);
      if (!graph_.coupled[c]) {
        for (long p = begin + r.begin; p < begin + r.end; ++p) {
          const int i = graph_.particles[p];
          if (!pinned_[i]) particle(x, i) = update_particle(model, anchors, h, t1, i, x);
        }
      } else {
        for (long p = begin + r.begin; p < begin + r.end; ++p) {
          const int i = graph_.particles[p];
          if (!pinned_[i]) particle(next_, i) = update_particle(model, anchors, h, t1, i, x);
        }
        if (parts > 1) {
#pragma omp barrier
        }
        for (long p = begin + r.begin; p < begin + r.end; ++p) {
          const int i = graph_.particles[p];
          if (!pinned_[i]) particle(x, i) = particle(next_, i);
        }
      }
      if (parts > 1) {
#pragma omp barrier
      }
    }
  });
  ++sweeps_;
}

StepResult Vbd::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Model& model = dynamics.model();
  prepare(model);
  const int n = model.num_particles();
  const int threads = dynamics.threads();
  ensure_size(f_, 3 * n);
  ensure_size(next_, 3 * n);
  // The inertial target y = x + h v + h^2 M^-1 f_ext: gravity, the model's external and added
  // forces and the seed model's contact forces, explicit over the step.
  for (int i = 0; i < n; ++i) particle(f_, i) = model.mass[i] * model.gravity;
  dynamics.add_applied_forces(s.t, s.x, s.v, f_);
  dynamics.contacts().add_forces(s.v, f_);
  x0_ = s.x;
  ensure_size(y_, 3 * n);
  for (int i = 0; i < n; ++i)
    particle(y_, i) =
        particle(s.x, i) + h * particle(s.v, i) + (h * h / model.mass[i]) * particle(f_, i);
  const Real t1 = s.t + h;
  // The first iterate: the inertial target, pinned particles on their paths at t1.
  s.x = y_;
  for (int k = 0; k < model.pins.size(); ++k)
    particle(s.x, model.pins.particles[k]) = model.pins.position(k, t1);
  penalty_terrains_.clear();
  if (dynamics.terrains() && options_.contact_hardness > 0) {
    for (const auto& terrain : *dynamics.terrains())
      if (terrain_contact_model(*terrain).constrains_solves())
        penalty_terrains_.push_back(terrain.get());
  }
  if (!penalty_terrains_.empty()) thickness::fill(model, gap_);
  const AnchorSprings* anchors = dynamics.anchors();
  if (anchors) {
    anchor_next_.assign(anchors->size(), -1);
    for (int a = static_cast<int>(anchors->size()) - 1; a >= 0; --a) {
      const int p = (*anchors)[a].particle;
      anchor_next_[a] = anchor_first_[p];
      anchor_first_[p] = a;
    }
  }
  // Chebyshev (Wang 2015, as Chen et al. 2024 Alg. 1): x(k) = omega_k (x(k) - x(k-2)) + x(k-2)
  // with omega_1 = 1, omega_2 = 2 / (2 - rho^2), omega_k = 4 / (4 - rho^2 omega_(k-1)).
  const Real rho = options_.chebyshev_rho;
  const bool chebyshev = rho > 0 && options_.iterations > 1;
  if (chebyshev) {
    previous_ = s.x;
    before_previous_ = s.x;
  }
  Real omega = 1;
  for (int it = 1; it <= options_.iterations; ++it) {
    sweep(model, anchors, h, t1, s.x, threads);
    if (!chebyshev) continue;
    omega = it == 1 ? 1 : it == 2 ? 2 / (2 - rho * rho) : 4 / (4 - rho * rho * omega);
    if (it >= 2) {
      // Pinned particles are equal in all three iterates: they stay on their paths.
      parallel::for_ranges(
          threads, 3L * n,
          [&](long b, long e) {
            for (long q = b; q < e; ++q) {
              const Real extrapolated =
                  omega * (s.x[q] - before_previous_[q]) + before_previous_[q];
              before_previous_[q] = previous_[q];
              s.x[q] = extrapolated;
              previous_[q] = extrapolated;
            }
          },
          parallel::kMinItemsPerThread, 3);
    } else {
      before_previous_ = previous_;
      previous_ = s.x;
    }
  }
  if (anchors) {
    for (const AnchorSpring& a : *anchors) anchor_first_[a.particle] = -1;
  }
  s.v = (s.x - x0_) / h;
  s.t = t1;
  if (!s.x.allFinite() || !s.v.allFinite())
    return StepResult::failure("vbd: a position or velocity is not finite");
  return StepResult::success();
}

}  // namespace jelly
