#include <jelly/solvers/integrators/vbd.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/forces.hpp>
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
  std::fill(pinned_.begin(), pinned_.end(), 0);
  for (int i : model.pins.particles) pinned_[i] = 1;
}

void Vbd::update_particle(const Model& model, const AnchorSprings* anchors, Real h, Real t1, int i,
                          VecX& x) const {
  const Springs& s = model.springs;
  const Real inv_h = 1.0 / h;
  const Vec3 xi(particle(x, i));
  const Vec3 moved_i = xi - Vec3(particle(x0_, i));  // h v_i at the iterate
  // The block of G at x_i: gradient -f (f the force on i) and Hessian H.
  const Real inertia = model.mass[i] * inv_h * inv_h;
  Vec3 f = -inertia * (xi - Vec3(particle(y_, i)));
  Eigen::Matrix3d hess = inertia * Eigen::Matrix3d::Identity();
  Eigen::Matrix3d elastic = Eigen::Matrix3d::Zero();  // the springs' part, for Rayleigh damping
  for (int e = graph_.spring_start[i]; e < graph_.spring_start[i + 1]; ++e) {
    const int k = graph_.spring[e], j = graph_.other[e];
    const Vec3 xj(particle(x, j));
    const Vec3 d = xi - xj;
    const Real length = d.norm();
    const Real rest = s.rest_length[k];
    Vec3 u;
    if (length >= kDegenerateLength * rest && length > 0) {
      u = d / length;
    } else {  // collapsed: the direction at rest, as xpbd
      const int sign = s.a[k] == i ? 1 : -1;
      u = sign * (Vec3(particle(model.rest_position, s.a[k])) -
                  Vec3(particle(model.rest_position, s.b[k])));
      const Real r = u.norm();
      if (!(r > 0)) continue;
      u /= r;
    }
    // Spring force -ks (L - l0) u and damper force -kd ((v_i - v_j) . u) u, with the
    // velocities of the step's backward-Euler v = (x - x^t) / h.
    const Real rate = (moved_i - (xj - Vec3(particle(x0_, j)))).dot(u) * inv_h;
    const Real ks = s.ks[k], kd = s.kd[k];
    f -= (ks * (length - rest) + kd * rate) * u;
    // -df_i/dx_i = ks u u^T + (ks (1 - l0/L) + kd c/L) P (P = I - u u^T) + (kd / h) u u^T,
    // each transverse term clamped at >= 0 (Choi and Ko 2002, implicit_euler's default).
    const Real transverse_elastic = length > 0 ? std::max<Real>(0, ks * (1 - rest / length)) : 0;
    const Real transverse_damper = length > 0 ? std::max<Real>(0, kd * rate / length) : 0;
    const Eigen::Matrix3d uu = u * u.transpose();
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - uu;
    const Eigen::Matrix3d spring_hess = ks * uu + transverse_elastic * p;
    elastic += spring_hess;
    hess += spring_hess + (kd * inv_h) * uu + transverse_damper * p;
  }
  if (options_.damping > 0) {  // Chen et al. 2024, eq. 14
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
  // Penalty contact: E = k d^2 / 2 below a coulomb surface at t1 (d < 0), force -k d n.
  for (const Terrain* terrain : penalty_terrains_) {
    if (!terrain->can_contact(xi, t1)) continue;
    const Real d = terrain->signed_distance(xi, t1);
    if (d >= 0) continue;
    const Vec3 normal = terrain->normal(xi, t1);
    const Real k = options_.contact_hardness * inertia;
    f -= k * d * normal;
    hess += k * normal * normal.transpose();
  }
  // H is symmetric positive definite (inertia + clamped, positive semidefinite terms).
  const Eigen::LLT<Eigen::Matrix3d> llt(hess);
  particle(x, i) = xi + llt.solve(f);
}

void Vbd::sweep(const Model& model, const AnchorSprings* anchors, Real h, Real t1, VecX& x,
                int threads) {
  const int team = parallel::team_size(threads, graph_.largest_colour(), kMinVbdParticlesPerThread);
  // One team for the sweep, colour after colour, a barrier between colours: within a colour
  // each particle reads only particles of other colours, so the result is that of any order.
  parallel::run(team, [&](int part, int parts) {
    for (int c = 0; c < graph_.colours(); ++c) {
      const long begin = graph_.colour_start[c], count = graph_.colour_start[c + 1] - begin;
      const parallel::Range r = parallel::split(count, part, parts);
      for (long p = begin + r.begin; p < begin + r.end; ++p) {
        const int i = graph_.particles[p];
        if (!pinned_[i]) update_particle(model, anchors, h, t1, i, x);
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
      if (terrain->contact().model == ContactModel::kCoulomb)
        penalty_terrains_.push_back(terrain.get());
  }
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
