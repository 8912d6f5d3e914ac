#include <jelly/solvers/adjoint/detail/projective_dynamics_adjoint.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

#include <jelly/core/detail/clock.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/adjoint/detail/adjoint_run.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/detail/projective_dynamics.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

namespace {

// The backward solves stop when |J^T lambda - b| <= this times |b|: far below the 1e-5 the
// gradients are checked to, far above round-off.
constexpr Real kPdBackwardTolerance = 1e-10;
constexpr int kPdBackwardMaxIterations = 2000;

// The preconditioner of the backward pass: the forward's own factor of the projective-dynamics
// matrix A = M / h^2 + L_ks + L_kd / h (shared by x, y and z; its pins held by a penalty), so
// that (h^2 A)^-1 approximates the inverse of J = M - h D - h^2 K. Nothing is factorized again.
class PdAdjointPreconditioner {
 public:
  PdAdjointPreconditioner(ProjectiveDynamics& pd, int np, Real h) : pd_(pd), scale_(1 / (h * h)) {
    rhs_.setZero(np, 3);
    solution_.setZero(np, 3);
  }

  // y = (h^2 A)^-1 x on the interleaved 3N layout.
  void apply(const VecX& x, VecX& y) {
    const Eigen::Index np = rhs_.rows();
    for (Eigen::Index i = 0; i < np; ++i)
      for (int c = 0; c < 3; ++c) rhs_(i, c) = x[3 * i + c];
    const LinearResult r = pd_.solve_with_factor(rhs_, solution_);
    if (!r.ok()) throw std::runtime_error("gradient: projective_dynamics' factor: " + r.message);
    for (Eigen::Index i = 0; i < np; ++i)
      for (int c = 0; c < 3; ++c) y[3 * i + c] = scale_ * solution_(i, c);
  }

 private:
  ProjectiveDynamics& pd_;
  Real scale_;
  Eigen::MatrixXd rhs_, solution_;
};

// BiCGSTAB (van der Vorst 1992) for J^T x = b, right-preconditioned by `pre`, from the x given.
// Returns the iterations, or -1 when it stopped above the tolerance.
struct PdBiCgStab {
  VecX r, r0, p, v, s, t, y, z;
  explicit PdBiCgStab(int n) {
    for (VecX* w : {&r, &r0, &p, &v, &s, &t, &y, &z}) w->setZero(n);
  }
  int solve(const SparseMatrix& j, PdAdjointPreconditioner& pre, const VecX& b, VecX& x) {
    // (Eigen runs a transposed product as a row-major one in an OpenMP region: kept on this
    // thread, whose spinning team would slow it down on a busy machine.)
    const parallel::SerialLibraries serial;
    const Real target = kPdBackwardTolerance * b.norm();
    r.noalias() = b - j.transpose() * x;
    if (r.norm() <= target) return 0;
    r0 = r;
    Real rho = 1, alpha = 1, omega = 1;
    v.setZero();
    p.setZero();
    for (int it = 1; it <= kPdBackwardMaxIterations; ++it) {
      const Real rho_next = r0.dot(r);
      if (rho_next == 0) return -1;
      const Real beta = (rho_next / rho) * (alpha / omega);
      rho = rho_next;
      p = r + beta * (p - omega * v);
      pre.apply(p, y);
      v.noalias() = j.transpose() * y;
      alpha = rho / r0.dot(v);
      x += alpha * y;
      s = r - alpha * v;
      if (s.norm() <= target) return it;
      pre.apply(s, z);
      t.noalias() = j.transpose() * z;
      const Real tt = t.squaredNorm();
      omega = tt > 0 ? t.dot(s) / tt : 0;
      x += omega * z;
      r = s - omega * t;
      if (r.norm() <= target) return it;
      if (omega == 0 || !std::isfinite(omega)) return -1;
    }
    return -1;
  }
};

// What one forward step leaves for the backward pass: the states at its start and end.
struct PdStepRecord {
  Real t = 0;
  VecX x0, v0, x1;
};

void pd_adjoint_check_supported(const Simulator& sim) {
  require(sim.forces().empty(), "added forces", sim.forces().size(),
          "none for gradients (forces' parameters are not differentiated yet)");
  require(sim.anchors().empty(), "anchors", sim.anchors().size(), "none for gradients");
  require(sim.terrains().empty(), "terrains", sim.terrains().size(),
          "none for projective_dynamics gradients (its contact by projection is not "
          "differentiated; implicit_euler's adjoint differentiates coulomb terrains)");
  require(!sim.body_contact().active(sim.model()), "body contact", "active",
          "none for projective_dynamics gradients (implicit_euler's adjoint differentiates "
          "contact between bodies)");
}

}  // namespace

GradientResult projective_dynamics_gradient(Simulator& sim, const GradientProblem& problem) {
  auto* pd = dynamic_cast<ProjectiveDynamics*>(&sim.integrator());
  require(pd != nullptr, "integrator", sim.integrator().name(),
          "projective_dynamics for projective_dynamics_gradient");
  pd_adjoint_check_supported(sim);
  const Model& model = sim.model();
  const AdjointFrames frames = check_gradient_problem(model, problem);
  const std::vector<int>& driven = frames.driven;
  const int steps = problem.steps;
  const int np = model.num_particles();
  const int n = 3 * np;
  const int pins = static_cast<int>(problem.driven_pins.size());
  std::vector<char> pinned(np, 0);
  for (int i : model.pins.particles) pinned[i] = 1;

  GradientResult out;
  const Real h = sim.options().dt;
  auto start = Clock::now();
  const int every = problem.checkpoint_every;
  const int segment = every > 0 ? std::min(every, steps) : steps;
  std::vector<PdStepRecord> records(segment);
  std::vector<SimulatorSnapshot> checkpoints;
  AdjointLoss loss(problem, frames, n);
  const auto not_converged = [&]() -> long {
    const Statistics stats = pd->statistics();
    const auto it = stats.find("not_converged");
    return it == stats.end() ? 0 : static_cast<long>(it->second);
  };
  std::vector<char> counted(steps, 0);
  const auto forward_step = [&](int k, PdStepRecord& r) {
    r.t = sim.state().t;
    r.x0 = sim.state().x;
    r.v0 = sim.state().v;
    for (int p = 0; p < pins; ++p) {
      const int i = problem.driven_pins[p];
      const Vec3 now = particle(r.x0, i);
      const Vec3& target = problem.pin_targets[static_cast<size_t>(k) * pins + p];
      sim.set_pin_target(i, now, (target - now) / h);
    }
    const long missed = not_converged();
    const StepResult result = sim.step();
    if (!result.ok)
      throw std::runtime_error("gradient: step " + std::to_string(k) +
                               " failed: " + result.message);
    r.x1 = sim.state().x;
    if (!counted[k]) {  // (a segment run again from its checkpoint is not counted twice)
      counted[k] = 1;
      if (not_converged() != missed) ++out.newton_unconverged_steps;
      const std::vector<Real>& residuals = pd->last_residuals();
      if (residuals.size() >= 2 && residuals.front() > 0)
        out.forward_residual = std::max(out.forward_residual, residuals.back() / residuals.front());
    }
  };
  loss.evaluate(0, sim.state());
  for (int k = 0; k < steps; ++k) {
    if (every > 0 && k % segment == 0) checkpoints.push_back(sim.snapshot());
    forward_step(k, records[every > 0 ? 0 : k]);
    loss.evaluate(k + 1, sim.state());
  }
  out.loss = loss.value();
  std::optional<SimulatorSnapshot> end_of_run;
  if (every > 0) end_of_run = sim.snapshot();
  out.forward_seconds = seconds_since(start);

  // Backward: per step from the last, the adjoint of its fixed point
  //   r(x1) = f(t1, x1, v) - M (v - v0) / h = 0 at the free particles,  v = (x1 - x0) / h,
  // the pinned particles' x1 on their paths (a driven pin's at its target). With H = -dr/dx1 =
  // M / h^2 - K - D / h (K, D the exact Jacobians at (x1, v)) and g the adjoint of x1,
  //   H^T lambda = g  (free rows; lambda = 0 at the pins),  then  dL/dp += lambda . dr/dp,
  // solved as J^T lambda = h^2 g with J = h^2 H = M - h D - h^2 K (implicit_euler's Newton
  // matrix), preconditioned by the forward's own factor of h^2 A = M + h^2 L_ks + h L_kd.
  start = Clock::now();
  out.backward_solver = "bicgstab_pd_prefactored";
  SpringJacobian jacobian(model);
  SparseMatrix k_matrix = jacobian.make_matrix(), d_matrix = jacobian.make_matrix(),
               j_matrix = jacobian.make_matrix();
  JacobianOptions exact;
  exact.definiteness = DefinitenessFix::kNone;
  exact.exact_damper = true;
  PdAdjointPreconditioner preconditioner(*pd, np, h);
  PdBiCgStab bicgstab(n);
  const AdjointBodies map = start_gradient_result(model, problem, out);
  const std::vector<int>& spring_body = map.spring_body;
  const std::vector<int>& particle_body = map.particle_body;
  const Springs& springs = model.springs;
  VecX damping(np), v(n), g(n), rhs(n), kl(n), dl(n);
  VecX xb = VecX::Zero(n), vb = VecX::Zero(n), x0b(n), v0b(n), lambda = VecX::Zero(n);
  if (loss.at(steps)) {
    xb = loss.dx(steps);
    vb = loss.dv(steps);
  }
  const int* outer = j_matrix.outerIndexPtr();
  const int* rows = j_matrix.innerIndexPtr();
  for (int begin = ((steps - 1) / segment) * segment; begin >= 0; begin -= segment) {
    const int end = std::min(begin + segment, steps);
    if (every > 0) {  // the segment's steps again, from its checkpoint
      sim.restore(checkpoints[begin / segment]);
      for (int k = begin; k < end; ++k) forward_step(k, records[k - begin]);
    }
    for (int k = end - 1; k >= begin; --k) {
      const PdStepRecord& r = records[k - begin];
      const Real t1 = r.t + h;
      // The end of the step: v1 = (x1 - x0) / h at the free particles; a fixed pin's x1 and v1
      // are its path's, a driven pin's x1 = target, v1 = (target - x0) / h.
      g = xb + vb / h;
      x0b = -vb / h;
      for (int i : model.pins.particles) {
        const int p = driven[i];
        if (p >= 0)
          out.pin_targets[static_cast<size_t>(k) * pins + p] += particle(g, i);
        else
          particle(x0b, i).setZero();
        particle(g, i).setZero();
      }
      v = (r.x1 - r.x0) / h;
      jacobian.assemble(model, r.x1, v, exact, k_matrix, d_matrix);
      if (!model.external_forces.empty()) {
        damping.setZero();
        add_external_damping(model.external_forces, t1, damping);
        for (int i = 0; i < np; ++i)
          if (damping[i] != 0)
            for (int d = 0; d < 3; ++d) jacobian.add_to_diagonal(d_matrix, 3 * i + d, -damping[i]);
      }
      {
        const Real* kv = k_matrix.valuePtr();
        const Real* dv = d_matrix.valuePtr();
        Real* jv = j_matrix.valuePtr();
        for (Eigen::Index q = 0; q < j_matrix.nonZeros(); ++q) jv[q] = -h * dv[q] - h * h * kv[q];
        for (int i = 0; i < np; ++i)
          for (int d = 0; d < 3; ++d) jacobian.add_to_diagonal(j_matrix, 3 * i + d, model.mass[i]);
        // The pins' rows and columns: the identity.
        for (int col = 0; col < n; ++col)
          for (int at = outer[col]; at < outer[col + 1]; ++at)
            if (pinned[col / 3] || pinned[rows[at] / 3]) jv[at] = rows[at] == col ? 1.0 : 0.0;
      }
      rhs = (h * h) * g;
      // (lambda starts from the later step's: consecutive steps' are close.)
      const int iterations = bicgstab.solve(j_matrix, preconditioner, rhs, lambda);
      if (iterations < 0 || !lambda.allFinite())
        throw std::runtime_error("gradient: the backward solve of step " + std::to_string(k) +
                                 " did not converge in " +
                                 std::to_string(kPdBackwardMaxIterations) + " iterations");
      out.backward_iterations += iterations;
      for (int i : model.pins.particles) particle(lambda, i).setZero();
      // x0 enters through v (dr/dx0 = M / h^2 - D / h), v0 through M v0 / h, a driven pin's
      // target through x1 (dr/dx1 = K + D / h at its columns).
      {
        const parallel::SerialLibraries serial;
        kl.noalias() = k_matrix.transpose() * lambda;
        dl.noalias() = d_matrix.transpose() * lambda;
      }
      for (int i = 0; i < np; ++i) {
        const Real m = model.mass[i];
        particle(x0b, i) += (m / (h * h)) * particle(lambda, i) - particle(dl, i) / h;
        particle(v0b, i) = (m / h) * particle(lambda, i);
      }
      for (int p = 0; p < pins; ++p) {
        const int i = problem.driven_pins[p];
        out.pin_targets[static_cast<size_t>(k) * pins + p] += particle(kl, i) + particle(dl, i) / h;
      }
      // Masses and gravity: r_i = m_i g - m_i (v_i - v0_i) / h + ...
      for (int i = 0; i < np; ++i) {
        if (pinned[i]) continue;
        const Vec3 l = particle(lambda, i);
        out.particle_mass[particle_body[i]] +=
            l.dot(model.gravity - (particle(v, i) - particle(r.v0, i)) / h);
        out.gravity += model.mass[i] * l;
      }
      // External forces at t1, on v = v1.
      add_external_force_gradients(model, t1, lambda, 1.0, v, particle_body, out);
      // Springs: f_a = -(ks (L - l0) + kd w.u) u at x1, w = v_a - v_b.
      for (int sp = 0; sp < springs.size(); ++sp) {
        const int ia = springs.a[sp], ib = springs.b[sp];
        const Vec3 d = particle(r.x1, ia) - particle(r.x1, ib);
        const Real length = d.norm();
        const Real l0 = springs.rest_length[sp];
        if (!(length > kDegenerateLength * l0)) continue;  // collapsed: not differentiated
        const Vec3 u = d / length;
        const Real al = (particle(lambda, ia) - particle(lambda, ib)).dot(u);
        const Real c = (particle(v, ia) - particle(v, ib)).dot(u);
        const size_t at = static_cast<size_t>(kSpringTypeCount) * spring_body[sp] +
                          static_cast<size_t>(springs.type[sp]);
        out.ks[at] -= (length - l0) * al;
        out.kd[at] -= c * al;
      }
      xb.swap(x0b);
      vb.swap(v0b);
      if (loss.at(k)) {
        xb += loss.dx(k);
        vb += loss.dv(k);
      }
    }
  }
  if (end_of_run) sim.restore(std::move(*end_of_run));
  out.initial_position = xb;
  out.initial_velocity = vb;
  out.backward_seconds = seconds_since(start);
  return out;
}

GradientResult integrator_gradient(Simulator& sim, const GradientProblem& problem) {
  const std::string_view name = sim.integrator().name();
  require(has_adjoint(name), "integrator", name,
          "implicit_euler or projective_dynamics for gradients");
  if (name == "projective_dynamics") return projective_dynamics_gradient(sim, problem);
  return implicit_euler_gradient(sim, problem);
}

bool has_adjoint(std::string_view integrator) {
  return integrator == "implicit_euler" || integrator == "projective_dynamics";
}

}  // namespace jelly
