#include <jelly/solvers/adjoint/detail/implicit_euler_adjoint.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <tuple>

#include <optional>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseLU>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/clock.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/adjoint/detail/adjoint_run.hpp>
#include <jelly/solvers/adjoint/detail/newton_backward.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/friction.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/solvers/linear/detail/cholmod_solver.hpp>
#include <jelly/solvers/linear/detail/ldlt_solver.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

namespace {

using Mat3 = Eigen::Matrix3d;
using Constraint = ImplicitEuler::SolvedConstraint;
using BodyPair = ImplicitEuler::SolvedPair;
using ConstraintKind = ImplicitEuler::SolvedConstraint::Kind;

// The projector S_c onto the free directions of a constrained particle (zero for a pin or a
// sticking contact, the tangent plane for a sliding one).
Mat3 adjoint_free_projector(const Constraint& c) {
  if (c.kind != ConstraintKind::kSlide) return Mat3::Zero();
  return Mat3::Identity() - c.normal * c.normal.transpose();
}

// Block (i, j) of a full-storage matrix of dense 3x3 blocks with sorted rows: the value index of
// its entry (3 i, 3 j) and the distance between its columns.
struct AdjointBlock {
  int at, stride;
};
AdjointBlock adjoint_block(const SparseMatrix& a, int i, int j) {
  const int* outer = a.outerIndexPtr();
  const int* rows = a.innerIndexPtr();
  const int* found = std::lower_bound(rows + outer[3 * j], rows + outer[3 * j + 1], 3 * i);
  return {static_cast<int>(found - rows), outer[3 * j + 1] - outer[3 * j]};
}
Mat3 adjoint_read(const SparseMatrix& a, const AdjointBlock& b) {
  Mat3 m;
  for (int q = 0; q < 3; ++q)
    for (int r = 0; r < 3; ++r) m(r, q) = a.valuePtr()[b.at + q * b.stride + r];
  return m;
}
void adjoint_write(SparseMatrix& a, const AdjointBlock& b, const Mat3& m) {
  for (int q = 0; q < 3; ++q)
    for (int r = 0; r < 3; ++r) a.valuePtr()[b.at + q * b.stride + r] = m(r, q);
}

// a -> S a S + C + I - S for the step's constraints, as ImplicitContact::constrain filters the
// forward system (`slot`: index into `cons` per particle, or -1; C = viscosity S on a sliding
// contact's diagonal block).
void adjoint_filter_system(SparseMatrix& a, const std::vector<Constraint>& cons,
                           const std::vector<int>& slot) {
  const int* outer = a.outerIndexPtr();
  const int* rows = a.innerIndexPtr();
  for (const Constraint& c : cons) {
    const int j = c.particle;
    const Mat3 sj = adjoint_free_projector(c);
    for (int at = outer[3 * j]; at < outer[3 * j + 1]; at += 3) {
      const int i = rows[at] / 3;
      const AdjointBlock bij = adjoint_block(a, i, j);
      const Mat3 block = adjoint_read(a, bij);
      if (i == j) {
        const Real viscosity = c.kind == ConstraintKind::kSlide ? c.viscosity : 0.0;
        adjoint_write(a, bij, sj * block * sj + viscosity * sj + Mat3::Identity() - sj);
        continue;
      }
      const Mat3 si = slot[i] >= 0 ? adjoint_free_projector(cons[slot[i]]) : Mat3::Identity();
      const Mat3 filtered = si * block * sj;
      adjoint_write(a, bij, filtered);
      adjoint_write(a, adjoint_block(a, j, i), filtered.transpose());
    }
  }
}

// Newton's backward solve: a sparse LU of the exact (non-symmetric) Jacobian up to this many
// unknowns (as "auto" picks CHOLMOD below the same size), BiCGSTAB with a Jacobi
// preconditioner to cg_tolerance above (an LU's fill grows too fast in 3D).
constexpr int kNewtonDirectMaxDofs = 1000;

// a -> S a S + C + I - S for a matrix of any symmetry (Newton's exact Jacobian): every block
// (i, j) with a constrained particle i or j becomes S_i a_ij S_j, a constrained diagonal block
// S a S + C + I - S.
void adjoint_filter_general(SparseMatrix& a, const std::vector<Constraint>& cons,
                            const std::vector<int>& slot) {
  if (cons.empty()) return;
  const int* outer = a.outerIndexPtr();
  const int* rows = a.innerIndexPtr();
  const int np = static_cast<int>(a.cols() / 3);
  for (int j = 0; j < np; ++j) {
    for (int at = outer[3 * j]; at < outer[3 * j + 1]; at += 3) {
      const int i = rows[at] / 3;
      if (slot[i] < 0 && slot[j] < 0) continue;
      const AdjointBlock bij = adjoint_block(a, i, j);
      const Mat3 block = adjoint_read(a, bij);
      const Mat3 si = slot[i] >= 0 ? adjoint_free_projector(cons[slot[i]]) : Mat3::Identity();
      const Mat3 sj = slot[j] >= 0 ? adjoint_free_projector(cons[slot[j]]) : Mat3::Identity();
      Mat3 f = si * block * sj;
      if (i == j) {
        const Constraint& c = cons[slot[i]];
        const Real viscosity = c.kind == ConstraintKind::kSlide ? c.viscosity : 0.0;
        f += viscosity * sj + Mat3::Identity() - sj;
      }
      adjoint_write(a, bij, f);
    }
  }
}

// The solver of the backward pass: the forward step's own kind (a direct factorization, or CG
// with the same preconditioner).
std::unique_ptr<LinearSolver> adjoint_backward_solver(std::string_view forward,
                                                      const ImplicitEulerOptions& o,
                                                      std::string& name) {
  CholmodOptions cholmod;
  cholmod.ordering = o.ordering;
  if (forward == "cholmod") {
    name = "cholmod";
    return std::make_unique<CholmodSolver>(cholmod);
  }
  if (forward == "ldlt") {
    name = "ldlt";
    return std::make_unique<LdltSolver>();
  }
  CgOptions cg;
  cg.preconditioner = forward == "cg_lagged_cholmod" ? CgPreconditioner::kLaggedCholesky
                                                     : CgPreconditioner::kJacobi;
  cg.tolerance = o.cg_tolerance;
  cg.max_iterations = o.cg_max_iterations;
  cg.refactor_iterations = o.refactor_iterations;
  cg.cholmod = cholmod;
  name = forward == "cg_lagged_cholmod" ? "cg_lagged_cholmod" : "cg_jacobi";
  return std::make_unique<CgSolver>(cg);
}

// The filtered diagonal block S D S + C + I - S of a constrained particle (row-major, in place).
void adjoint_filter_block(const Constraint& c, Real block[9]) {
  Mat3 d;
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) d(r, q) = block[3 * r + q];
  const Mat3 s = adjoint_free_projector(c);
  const Real viscosity = c.kind == ConstraintKind::kSlide ? c.viscosity : 0.0;
  const Mat3 f = s * d * s + viscosity * s + Mat3::Identity() - s;
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) block[3 * r + q] = f(r, q);
}

// The backward solves of a step whose forward solve was the matrix-free block-Jacobi CG: the same
// system (BandSystem, in the same precision), filtered the same way, and the same preconditioner.
struct MatrixFreeBackward {
  SpringBands bands;
  BandSystem band;
  MatrixFreeCg cg;
  std::vector<Real> projectors, viscosities;
  MatrixFreeBackward(const Model& model, bool single)
      : bands(model), band(bands, model.num_particles(), single) {}
};

// What one forward step leaves for the backward pass.
struct StepRecord {
  Real t = 0;     // the time at the start of the step
  VecX x, v, dv;  // the state at the start of the step, and its velocity change
  std::vector<Constraint> constraints;
  std::vector<BodyPair> pairs;  // the active contact pairs between bodies of the final solve
};

// Adds the coupling block H = kappa m n n^T + c P_t of each pair to `a` (+H at (i, i) and
// (j, j), -H at (i, j) and (j, i)), as ImplicitBodyContact::add_terms does; `a`'s pattern holds
// the pairs' blocks.
void adjoint_add_pair_blocks(SparseMatrix& a, const std::vector<BodyPair>& pairs) {
  for (const BodyPair& p : pairs) {
    const Mat3 nn = p.normal * p.normal.transpose();
    const Real c = p.slide ? p.viscosity : p.kappa * p.mass;
    const Mat3 block = (p.kappa * p.mass) * nn + c * (Mat3::Identity() - nn);
    for (const auto& [r, q, sign] : {std::tuple{p.i, p.i, 1.0}, std::tuple{p.j, p.j, 1.0},
                                     std::tuple{p.i, p.j, -1.0}, std::tuple{p.j, p.i, -1.0}}) {
      const AdjointBlock b = adjoint_block(a, r, q);
      adjoint_write(a, b, adjoint_read(a, b) + sign * block);
    }
  }
}

// A sliding pair's friction viscosity `value` at the step after r, if r's final solve set it
// (ImplicitBodyContact::update on the pair `p` as that solve held it, recomputed with the same
// arithmetic): adds cbar dvalue/d(...) to the adjoints of r's velocity change, initial state and
// masses and returns true; false (nothing added) when it came from elsewhere (a new pair's
// prediction, a solve before the last, or the run's start).
bool adjoint_trace_pair_viscosity(const BodyPair& p, Real value, Real cbar, Real mu, Real mu_s,
                                  Real h, const StepRecord& r, const VecX& inverse_mass,
                                  const std::vector<int>& particle_body, VecX& dvb, VecX& v0b,
                                  VecX& x0b, std::vector<Real>& mass_bar) {
  using friction::tangential;
  const Vec3& n = p.normal;
  const Vec3 w1 =
      particle(r.v, p.j) + particle(r.dv, p.j) - particle(r.v, p.i) - particle(r.dv, p.i);
  const Real c = p.slide ? p.viscosity : p.kappa * p.mass;
  const Real gap1 = p.gap0 + h * n.dot(w1);
  const Vec3 q = (-(p.kappa * p.mass / h) * gap1) * n - c * tangential(w1, n);
  const Real pn = q.dot(n);
  if (!(pn >= 0)) return false;
  const Real km = p.kappa * p.mass, bn = n.dot(w1);
  const Vec3 wt = tangential(w1, n);
  const Real speed = wt.norm();
  if (!(speed > 0)) return false;
  Vec3 d_w, d_n;
  Real d_gap;
  if (p.slide) {  // c = mu p_n / |w1_t|
    if (!(mu > 0)) return false;
    const Real set = mu * pn / std::max(speed, 1e-300);
    if ((mu_s > 0 && set >= friction::kStickViscosity * p.mass) || set != value) return false;
    d_w = -(mu * km / speed) * n - (value / (speed * speed)) * wt;
    d_gap = -(mu / speed) * (km / h);
    d_n = -(mu * km / speed) * w1 + (value * bn / (speed * speed)) * wt;
  } else {  // stick -> slide: c = mu p_n m / (p_t - mu p_n), p_t = kappa m |w1_t|
    const Real pt = tangential(q, n).norm();
    if (!(pt > mu_s * pn)) return false;
    const Real force = mu * pn;
    if (!(pt > force)) return false;
    const Real set = force * p.mass / (pt - force);
    if (set != value) return false;
    const Real d = pt - force;
    const Real a_pn = (mu * p.mass / d) * (1 + force / d), a_pt = -value / d;
    d_w = -(a_pn * km) * n + (a_pt * km / speed) * wt;
    d_gap = -a_pn * km / h;
    d_n = -(a_pn * km) * w1 - (a_pt * km * bn / speed) * wt;
  }
  // value is proportional to the pair's mass m (p_n, p_t and m all are).
  const Real d_m = value / p.mass;
  const Vec3 gw = cbar * d_w;
  particle(dvb, p.j) += gw;
  particle(v0b, p.j) += gw;
  particle(dvb, p.i) -= gw;
  particle(v0b, p.i) -= gw;
  const Real length = (particle(r.x, p.j) - particle(r.x, p.i)).norm();
  const Vec3 gd = cbar * (d_gap * n + tangential(d_n, n) / length);
  particle(x0b, p.j) += gd;
  particle(x0b, p.i) -= gd;
  for (const int k : {p.i, p.j})
    mass_bar[particle_body[k]] += cbar * d_m * p.mass * p.mass * inverse_mass[k] * inverse_mass[k];
  return true;
}

void adjoint_check_supported(const Simulator& sim, const ImplicitEuler& ie) {
  const ImplicitEulerOptions& o = ie.options();
  require(sim.forces().empty(), "added forces", sim.forces().size(),
          "none for gradients (forces' parameters are not differentiated yet)");
  require(sim.anchors().empty(), "anchors", sim.anchors().size(), "none for gradients");
  require(o.contact == ImplicitContactMode::kImplicit || !sim.body_contact().active(sim.model()),
          "integrator.contact", "\"after_step\"",
          "\"implicit\" for gradients of a run with contact between bodies (resolved after the "
          "step, it is not differentiated)");
  for (int k = 0; k < static_cast<int>(sim.terrains().size()); ++k) {
    const ContactParams& c = sim.terrains()[k]->contact();
    require(c.model == ContactModel::kCoulomb && o.contact == ImplicitContactMode::kImplicit,
            "terrains[" + std::to_string(k) + "].contact.model", contact_model_name(c.model),
            "\"coulomb\" with the integrator's contact = \"implicit\" for gradients");
  }
}

}  // namespace

GradientResult implicit_euler_gradient(Simulator& sim, const GradientProblem& problem) {
  auto* ie = dynamic_cast<ImplicitEuler*>(&sim.integrator());
  require(ie != nullptr, "integrator", sim.integrator().name(), "implicit_euler for gradients");
  adjoint_check_supported(sim, *ie);
  const AdjointFrames frames = check_gradient_problem(sim.model(), problem);
  const std::vector<int>& driven = frames.driven;
  const int steps = problem.steps;
  const int np = sim.model().num_particles();
  const int n = 3 * np;
  const int pins = static_cast<int>(problem.driven_pins.size());

  GradientResult out;
  const Real h = sim.options().dt;
  // Forward: the states, velocity changes, constraint sets and the loss terms' derivatives.
  auto start = Clock::now();
  // Stored steps: all of them, or with checkpoints one segment's (recomputed backwards).
  const int every = problem.checkpoint_every;
  const int segment = every > 0 ? std::min(every, steps) : steps;
  std::vector<StepRecord> records(segment);
  std::vector<SimulatorSnapshot> checkpoints;
  AdjointLoss loss(problem, frames, n);
  // Contact between bodies: the union of the pairs' blocks (the backward matrix's pattern), and
  // what the adjoint holds (the end of step's projection of deep overlaps, restitution).
  std::vector<std::pair<int, int>> pair_blocks;
  std::vector<char> counted(steps, 0);
  const Real restitution = sim.body_contact().params().restitution;
  const Real resting_speed = sim.body_contact().params().resting_speed;
  const auto body_projections = [&]() -> long {
    const Statistics stats = sim.integrator().statistics();
    const auto it = stats.find("body_contact_projected");
    return it == stats.end() ? 0 : static_cast<long>(it->second);
  };
  long projected_so_far = body_projections();
  // Step k of the run, recorded into r.
  const auto forward_step = [&](int k, StepRecord& r) {
    r.t = sim.state().t;
    r.x = sim.state().x;
    r.v = sim.state().v;
    for (int p = 0; p < pins; ++p) {
      const int i = problem.driven_pins[p];
      const Vec3 now = particle(r.x, i);
      const Vec3& target = problem.pin_targets[static_cast<size_t>(k) * pins + p];
      sim.set_pin_target(i, now, (target - now) / h);
    }
    const StepResult result = sim.step();
    if (!result.ok)
      throw std::runtime_error("gradient: step " + std::to_string(k) +
                               " failed: " + result.message);
    const auto* integrator = dynamic_cast<const ImplicitEuler*>(&sim.integrator());
    r.dv = integrator->last_velocity_change();
    r.constraints = integrator->last_constraints();
    r.pairs = integrator->last_pairs();
    if (!counted[k]) {  // (a segment run again from its checkpoint is not counted twice)
      counted[k] = 1;
      if (!integrator->last_converged()) ++out.newton_unconverged_steps;
      if (integrator->last_step_had_body_contact()) {  // (only candidates can be projected)
        const long projected = body_projections();
        if (projected != projected_so_far) ++out.pair_projected_steps;
        projected_so_far = projected;
      }
      for (const BodyPair& p : r.pairs) {
        pair_blocks.emplace_back(p.i, p.j);
        ++out.pair_steps;
        if (restitution > 0 && p.approach > resting_speed) ++out.pair_bounce_steps;
      }
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

  // Backward: per step from the last, the adjoint of
  //   dv = y + z,  (S A S + C + I - S) y = S (b - A z - C w0),  v1 = v0 + dv,  x1 = x0 + h v1,
  // then the contacts' normal velocity zeroed and the pins set on their paths.
  start = Clock::now();
  const Model& model = sim.model();
  const ImplicitEulerOptions& options = ie->options();
  JacobianOptions jacobian_options;
  jacobian_options.definiteness = options.definiteness;
  const int threads = std::max(1, sim.options().threads);
  // The matrix-free forward path: its own system and preconditioner; else an assembled matrix.
  std::optional<MatrixFreeBackward> free;
  std::optional<SpringJacobian> jacobian;
  SparseMatrix a, filtered;
  std::unique_ptr<LinearSolver> solver;
  std::sort(pair_blocks.begin(), pair_blocks.end());
  pair_blocks.erase(std::unique(pair_blocks.begin(), pair_blocks.end()), pair_blocks.end());
  // Newton (newton_iterations > 1): the adjoint of the converged step, by the implicit function
  // theorem at the last iterate v1: the exact Jacobian J = M - h D - h^2 K (+ the pairs' and the
  // wind's terms) at (x1, v1), its damper term non-symmetric, transposed in a sparse LU.
  const bool newton = options.newton_iterations > 1;
  std::optional<Eigen::SparseLU<SparseMatrix>> lu;
  std::optional<Eigen::BiCGSTAB<SparseMatrix, Eigen::DiagonalPreconditioner<Real>>> bicgstab;
  SparseMatrix transposed;
  SparseMatrix k_matrix, d_matrix;
  JacobianOptions exact_options;
  exact_options.definiteness = DefinitenessFix::kNone;
  exact_options.exact_damper = true;
  VecX x1(n), v1(n);
  // Newton after a matrix-free forward (no pairs between bodies): its band system, exact, and
  // BiCGSTAB with block Jacobi (solvers/adjoint/detail/newton_backward.hpp).
  std::optional<MatrixFreeNewtonBackward> newton_free;
  std::vector<Real> newton_projectors, newton_viscosities;
  if (newton && ie->linear_solver_name() == "cg_jacobi_matrix_free" && pair_blocks.empty()) {
    newton_free.emplace(model, options.cg_tolerance >= 1e-6);
    out.backward_solver = "bicgstab_block_jacobi_matrix_free";
  } else if (newton) {
    jacobian.emplace(model, pair_blocks);
    a = jacobian->make_matrix();
    filtered = jacobian->make_matrix();
    k_matrix = jacobian->make_matrix();
    d_matrix = jacobian->make_matrix();
    if (n <= kNewtonDirectMaxDofs) {
      lu.emplace();
      lu->analyzePattern(filtered);
      out.backward_solver = "sparse_lu";
    } else {
      bicgstab.emplace();
      bicgstab->setTolerance(options.cg_tolerance);
      bicgstab->setMaxIterations(options.cg_max_iterations);
      out.backward_solver = "bicgstab_jacobi";
    }
  } else if (ie->linear_solver_name() == "cg_jacobi_matrix_free") {
    // (the forward step assembles its matrix when bodies may touch)
    if (!pair_blocks.empty())
      throw std::logic_error("gradient: contact pairs between bodies on the matrix-free path");
    free.emplace(model, options.cg_tolerance >= 1e-6);
    out.backward_solver = "cg_jacobi_matrix_free";
  } else {
    jacobian.emplace(model, pair_blocks);
    a = jacobian->make_matrix();
    filtered = jacobian->make_matrix();
    solver = adjoint_backward_solver(ie->linear_solver_name(), options, out.backward_solver);
    if (LinearResult r = solver->analyze(a); !r.ok())
      throw std::runtime_error("gradient: " + r.message);
  }
  const AdjointBodies map = start_gradient_result(model, problem, out);
  const std::vector<int>& spring_body = map.spring_body;
  const std::vector<int>& particle_body = map.particle_body;
  std::vector<int> slot(np, -1);
  // The inverse masses the body contact gives its pairs (0 for pins).
  VecX inverse_mass = model.mass.cwiseInverse();
  for (int k = 0; k < model.pins.size(); ++k) inverse_mass[model.pins.particles[k]] = 0;
  // The sliding contacts of the step after the current one: dL/d(their viscosity), to be traced
  // to the current step's solve.
  struct PendingViscosity {
    int particle;
    Real cbar, value;
  };
  std::vector<PendingViscosity> pending;
  // The same for the sliding contact pairs between bodies of the step after the current one.
  struct PendingPairViscosity {
    int i, j;
    Real cbar, value;
  };
  std::vector<PendingPairViscosity> pending_pairs;
  std::vector<int> pair_order;  // the current step's pairs sorted by (i, j)
  const Real pair_mu = sim.body_contact().params().friction;
  const Real pair_mu_s = sim.body_contact().params().static_friction;
  VecX damping(np);
  VecX e_vec = VecX::Zero(n), a_e(n);
  VecX xb = VecX::Zero(n), vb = VecX::Zero(n), x0b(n), v0b(n), dvb(n), mu = VecX::Zero(n),
       lambda(n), a_lambda(n), kw(n);
  if (loss.at(steps)) {
    xb = loss.dx(steps);
    vb = loss.dv(steps);
  }
  const Springs& springs = model.springs;
  const Real* rest = springs.rest_length.data();
  for (int begin = ((steps - 1) / segment) * segment; begin >= 0; begin -= segment) {
    const int end = std::min(begin + segment, steps);
    if (every > 0) {  // the segment's steps again, from its checkpoint
      sim.restore(checkpoints[begin / segment]);
      for (int k = begin; k < end; ++k) forward_step(k, records[k - begin]);
    }
    for (int k = end - 1; k >= begin; --k) {
      const StepRecord& r = records[k - begin];
      const std::vector<Constraint>& cons = r.constraints;
      for (size_t ci = 0; ci < cons.size(); ++ci) slot[cons[ci].particle] = static_cast<int>(ci);
      // The pins' end of step: x1 = target, v1 = (target - x0) / h for a driven pin (a path's,
      // independent of the state, for the others); vel_bar collects dL/d(v1) of the driven pins.
      std::vector<Vec3> vel_bar(pins, Vec3::Zero());
      for (const Constraint& c : cons) {
        if (c.kind != ConstraintKind::kPin) continue;
        const int p = driven[c.particle];
        if (p >= 0) {
          out.pin_targets[static_cast<size_t>(k) * pins + p] += particle(xb, c.particle);
          vel_bar[p] += particle(vb, c.particle);
        }
        particle(xb, c.particle).setZero();
        particle(vb, c.particle).setZero();
      }
      // The contacts' end of step: (v1 - u).n = 0.
      for (const Constraint& c : cons) {
        if (c.kind == ConstraintKind::kPin) continue;
        ++out.contact_steps;
        if (c.bounces) ++out.bounce_steps;
        auto w = particle(vb, c.particle);
        w -= c.normal * c.normal.dot(w);
      }
      // x1 = x0 + h v1, v1 = v0 + dv (Newton: v1 is the unknown, v0 enters through M (v1 - v0)).
      x0b = xb;
      dvb = vb + h * xb;
      if (newton)
        v0b.setZero();
      else
        v0b = dvb;
      // The forward step's matrix, filtered by its constraints; mu = filtered^-1 dvb, lambda = S
      // mu.
      if (newton_free) {
        v1 = r.v + r.dv;
        x1 = r.x + h * v1;
        if (!newton_free->assemble(model, x1, v1, h, threads))
          throw std::runtime_error("gradient: a spring collapsed at step " + std::to_string(k));
      } else if (newton) {
        v1 = r.v + r.dv;
        x1 = r.x + h * v1;
        jacobian->assemble(model, x1, v1, exact_options, k_matrix, d_matrix, threads);
        const Real* dv_values = d_matrix.valuePtr();
        const Real* k_values = k_matrix.valuePtr();
        Real* a_values = a.valuePtr();
        for (Eigen::Index q = 0; q < a.nonZeros(); ++q)
          a_values[q] = -h * dv_values[q] - (h * h) * k_values[q];
        for (int i = 0; i < np; ++i)
          for (int d = 0; d < 3; ++d) jacobian->add_to_diagonal(a, 3 * i + d, model.mass[i]);
        adjoint_add_pair_blocks(a, r.pairs);
      } else if (free) {
        if (!free->band.assemble(model, r.x, r.v, options.definiteness, h, h * h, r.v, kw, threads))
          throw std::runtime_error("gradient: a spring collapsed at step " + std::to_string(k));
      } else {
        jacobian->assemble_system(model, r.x, r.v, jacobian_options, h, h * h, a, r.v, kw);
        adjoint_add_pair_blocks(a, r.pairs);
      }
      // The forces (and the wind's drag in A) are taken at the end of the step, t + h.
      const Real t1 = r.t + h;
      if (!model.external_forces.empty()) {
        damping.setZero();
        add_external_damping(model.external_forces, t1, damping);
        for (int i = 0; i < np; ++i) {
          if (damping[i] == 0) continue;
          if (newton_free)
            newton_free->add_diagonal(i, h * damping[i]);
          else if (free)
            free->band.add_diagonal(i, h * damping[i]);
          else
            for (int d = 0; d < 3; ++d) jacobian->add_to_diagonal(a, 3 * i + d, h * damping[i]);
        }
      }
      // The next step's friction viscosities that this step's final solve set (ImplicitContact::
      // update): a sliding contact's c = mu p_n / |(v1 - u)_t|, a sticking one's switch to sliding
      // c = mu m p_n / (|p_t| - mu p_n), with p = (A dv - b)_i. Their adjoints: v1 through the
      // speed, and p through e: e^T (A dv - b) adds A e to dvb, and -e to lambda in phi below.
      e_vec.setZero();
      bool traced_any = false;
      // (Newton: the viscosities came from the linearized solve before the iterations, which is
      // not recorded: held.)
      if (newton) {
        for (const PendingViscosity& pv : pending)
          if (pv.value != 0) ++out.slide_steps;
        pending.clear();
        out.pair_slide_steps += static_cast<long>(pending_pairs.size());
        pending_pairs.clear();
      }
      for (const PendingViscosity& pv : pending) {
        const int ci = slot[pv.particle];
        const Constraint* c = ci >= 0 ? &cons[ci] : nullptr;
        bool traced = false;
        if (c != nullptr && c->kind != ConstraintKind::kPin) {
          const Vec3& nn = c->normal;
          const Vec3 p = c->impulse;
          const Real pn = p.dot(nn);
          const Real m = model.mass[pv.particle];
          if (c->kind == ConstraintKind::kSlide) {
            const Vec3 w =
                particle(r.v, pv.particle) + particle(r.dv, pv.particle) - c->surface_velocity;
            const Vec3 wt = w - w.dot(nn) * nn;
            const Real speed = wt.norm();
            const Real value = c->friction * pn / std::max(speed, 1e-300);
            if (value == pv.value && speed > 0) {
              traced = true;
              const Vec3 speed_bar = (-pv.cbar * value / speed / speed) * wt;
              particle(dvb, pv.particle) += speed_bar;
              particle(v0b, pv.particle) += speed_bar;
              particle(e_vec, pv.particle) += (pv.cbar * c->friction / speed) * nn;
            }
          } else {
            const Vec3 pt = p - pn * nn;
            const Real pt_norm = pt.norm();
            const Real force = c->friction * pn;
            if (pt_norm > c->static_friction * pn && pt_norm > force) {
              const Real value = force * m / (pt_norm - force);
              if (value == pv.value) {
                traced = true;
                const Real d = pt_norm - force;
                const Real d_pn = (c->friction * m / d) * (1 + force / d);
                const Real d_pt = -value / d;
                particle(e_vec, pv.particle) += pv.cbar * (d_pn * nn + d_pt * pt / pt_norm);
                out.particle_mass[particle_body[pv.particle]] += pv.cbar * value / m;
              }
            }
          }
        }
        traced_any = traced_any || traced;
        if (!traced && pv.value != 0) ++out.slide_steps;
      }
      // The next step's sliding pairs' viscosities that this step's final solve set
      // (ImplicitBodyContact::update, from the pair's impulse q(w1), an explicit function of this
      // step's x0 (n, gap0), w1 = v1_j - v1_i and masses): a sliding pair's c = mu p_n / |w1_t|, a
      // sticking one's switch to sliding c = mu p_n m / (p_t - mu p_n), p_n = -kappa m g1 / h.
      // Recomputed here as the forward step computed it, and traced when it is the value the
      // next step used.
      if (!pending_pairs.empty()) {
        pair_order.resize(r.pairs.size());
        for (size_t q = 0; q < r.pairs.size(); ++q) pair_order[q] = static_cast<int>(q);
        const auto key = [&](int q) { return std::make_pair(r.pairs[q].i, r.pairs[q].j); };
        std::sort(pair_order.begin(), pair_order.end(),
                  [&](int a1, int b1) { return key(a1) < key(b1); });
        for (const PendingPairViscosity& pv : pending_pairs) {
          const auto found =
              std::lower_bound(pair_order.begin(), pair_order.end(), std::make_pair(pv.i, pv.j),
                               [&](int q, const std::pair<int, int>& k2) { return key(q) < k2; });
          const bool traced =
              found != pair_order.end() && key(*found) == std::make_pair(pv.i, pv.j) &&
              adjoint_trace_pair_viscosity(r.pairs[*found], pv.value, pv.cbar, pair_mu, pair_mu_s,
                                           h, r, inverse_mass, particle_body, dvb, v0b, x0b,
                                           out.particle_mass);
          if (!traced) ++out.pair_slide_steps;
        }
        pending_pairs.clear();
      }
      if (traced_any) {
        if (free)
          free->band.multiply(e_vec, a_e, threads);
        else
          a_e.noalias() = a * e_vec;
        dvb += a_e;
      }
      // The forward step's matrix, filtered by its constraints; mu = filtered^-1 dvb, lambda = S
      // mu.
      LinearResult solved;
      if (newton_free) {
        newton_projectors.resize(9 * cons.size());
        newton_viscosities.resize(cons.size());
        for (size_t ci = 0; ci < cons.size(); ++ci) {
          const Mat3 sc = adjoint_free_projector(cons[ci]);
          std::copy(sc.data(), sc.data() + 9, newton_projectors.data() + 9 * ci);
          newton_viscosities[ci] =
              cons[ci].kind == ConstraintKind::kSlide ? cons[ci].viscosity : 0.0;
        }
        const ProductFilter filter =
            cons.empty()
                ? ProductFilter{}
                : ProductFilter{slot.data(), newton_projectors.data(), newton_viscosities.data()};
        // (mu starts from the later step's adjoint: consecutive steps' are close.)
        solved = newton_free->solve(dvb, mu, filter, options.cg_tolerance,
                                    options.cg_max_iterations, threads);
        if (!solved.ok() || !mu.allFinite())
          throw std::runtime_error("gradient: the backward solve of step " + std::to_string(k) +
                                   " failed: " + solved.message);
        out.backward_iterations += solved.iterations;
      } else if (newton) {
        std::copy(a.valuePtr(), a.valuePtr() + a.nonZeros(), filtered.valuePtr());
        adjoint_filter_general(filtered, cons, slot);
        bool ok = false;
        std::string why;
        if (lu) {
          lu->factorize(filtered);
          if (lu->info() == Eigen::Success) mu = lu->transpose().solve(dvb);
          ok = lu->info() == Eigen::Success;
          why = "the Newton step's Jacobian is singular (" + lu->lastErrorMessage() + ")";
        } else {
          transposed = filtered.transpose();
          bicgstab->compute(transposed);
          mu = bicgstab->solve(dvb);
          ok = bicgstab->info() == Eigen::Success;
          why = "BiCGSTAB did not reach cg_tolerance in cg_max_iterations";
        }
        if (!ok || !mu.allFinite())
          throw std::runtime_error("gradient: the backward solve of step " + std::to_string(k) +
                                   " failed: " + why);
      } else if (free) {
        free->projectors.resize(9 * cons.size());
        free->viscosities.resize(cons.size());
        for (size_t ci = 0; ci < cons.size(); ++ci) {
          const Mat3 sc = adjoint_free_projector(cons[ci]);
          std::copy(sc.data(), sc.data() + 9, free->projectors.data() + 9 * ci);
          free->viscosities[ci] =
              cons[ci].kind == ConstraintKind::kSlide ? cons[ci].viscosity : 0.0;
        }
        const ProductFilter filter =
            cons.empty()
                ? ProductFilter{}
                : ProductFilter{slot.data(), free->projectors.data(), free->viscosities.data()};
        solved = free->cg.set_diagonal_blocks(
            np,
            [&](int i, Real d[9]) {
              free->band.diagonal_block(i, d);
              if (slot[i] >= 0) adjoint_filter_block(cons[slot[i]], d);
            },
            threads);
        if (solved.ok()) {
          solved = free->cg.solve(
              [&](const VecX& in, VecX& y) { free->band.multiply(in, y, threads, filter); }, dvb,
              mu, options.cg_tolerance, options.cg_max_iterations, threads);
          out.backward_iterations += solved.iterations;
        }
      } else {
        std::copy(a.valuePtr(), a.valuePtr() + a.nonZeros(), filtered.valuePtr());
        adjoint_filter_system(filtered, cons, slot);
        solved = solver->factorize(filtered);
        if (solved.ok()) solved = solver->solve(dvb, mu);
      }
      if (!newton && !solved.ok())
        throw std::runtime_error("gradient: the backward solve of step " + std::to_string(k) +
                                 " failed: " + solved.message);
      lambda = mu;
      for (const Constraint& c : cons)
        particle(lambda, c.particle) = adjoint_free_projector(c) * particle(mu, c.particle);
      // The prescribed velocity changes z (and the sliding friction's C w0): their adjoint is
      // dvb - A lambda at the constrained particles.
      if (!cons.empty()) {
        if (newton_free) {
          newton_free->multiply_transposed(lambda, a_lambda, threads);
        } else if (newton) {
          // (Eigen runs a transposed sparse product in an OpenMP region: kept on this thread.)
          const parallel::SerialLibraries serial;
          a_lambda.noalias() = a.transpose() * lambda;
        } else if (free) {
          free->band.multiply(lambda, a_lambda, threads);
        } else {
          a_lambda.noalias() = a * lambda;
        }
      }
      // (Newton: v1 of a constrained particle is prescribed whatever v0 (z = ... - v0 cancels
      // v1 = v0 + dv); the free ones see v0 through M (v1 - v0) only.)
      if (newton)
        for (int i = 0; i < np; ++i) particle(v0b, i) += model.mass[i] * particle(lambda, i);
      for (const Constraint& c : cons) {
        const int i = c.particle;
        const Vec3 zb = particle(dvb, i) - particle(a_lambda, i);
        const Vec3& nn = c.normal;
        switch (c.kind) {
          case ConstraintKind::kPin: {  // z = v_path - v0
            if (!newton) particle(v0b, i) -= zb;
            const int p = driven[i];
            if (p >= 0) vel_bar[p] += zb;
            break;
          }
          case ConstraintKind::kStick:  // z = u_t + (-d(x0) / h) n - v0
            if (!newton) particle(v0b, i) -= zb;
            particle(x0b, i) -= (nn.dot(zb) / h) * nn;
            break;
          case ConstraintKind::kSlide: {  // z = (-d(x0) / h - v0.n) n; rhs -= c P_t (v0 - u)
            particle(x0b, i) -= (nn.dot(zb) / h) * nn;
            if (newton) break;  // (Newton's friction is -c P_t (v1 - u): no v0)
            particle(v0b, i) -= nn.dot(zb) * nn;
            const Vec3 l = particle(lambda, i);
            particle(v0b, i) -= c.viscosity * (l - l.dot(nn) * nn);
            break;
          }
        }
      }
      for (int p = 0; p < pins; ++p) {
        const int i = problem.driven_pins[p];
        out.pin_targets[static_cast<size_t>(k) * pins + p] += vel_bar[p] / h;
        particle(x0b, i) -= vel_bar[p] / h;
      }
      // The sliding contacts' viscosity c: Af's C = c P_t and rhs's -c P_t (v0 - u) give
      // dL/dc = -lambda_i . (v1 - u)_t, sent to the step whose solve set c (the previous one).
      pending.clear();
      for (const Constraint& c : cons) {
        if (c.kind != ConstraintKind::kSlide) continue;
        const Vec3 w = particle(r.v, c.particle) + particle(r.dv, c.particle) - c.surface_velocity;
        const Vec3 wt = w - w.dot(c.normal) * c.normal;
        pending.push_back({c.particle, -particle(lambda, c.particle).dot(wt), c.viscosity});
      }
      if (traced_any) lambda -= e_vec;
      // phi = lambda^T (b - A dv) with b = h (f + h K v), A = M - h D - h^2 K at (x0, v0), lambda
      // and dv held: its derivatives with respect to x0, v0 and the parameters.
      // Masses and gravity: phi_i = m_i lambda_i . (h g - dv_i).
      for (int i = 0; i < np; ++i) {
        const Vec3 l = particle(lambda, i);
        out.particle_mass[particle_body[i]] += l.dot(h * model.gravity - particle(r.dv, i));
        out.gravity += (h * model.mass[i]) * l;
      }
      // External forces at t1 (b = h (f + ...)), the wind's drag on v1 = v0 + dv; the drag also
      // in A = M + h drag - ...: phi_i = h lambda_i . f_i - h drag lambda_i . dv_i on a wind
      // particle, whose v0 term the linearized step takes.
      if (!model.external_forces.empty()) {
        v1 = r.v + r.dv;
        add_external_force_gradients(model, t1, lambda, h, v1, particle_body, out);
        for (const ExternalForce& force : model.external_forces) {
          if (newton || force.kind != ExternalForceKind::kWind || t1 < force.start ||
              t1 >= force.end)
            continue;
          for (int i : force.particles) particle(v0b, i) -= (h * force.drag) * particle(lambda, i);
        }
      }
      // Springs, per spring with d = xa - xb, L = |d|, u = d / L, w = va - vb, and the differences
      // l, e of lambda and dv at its ends (q = w + e):
      //   phi / h = -ks (L - l0) a - kd a (c + be) - h ks a g + h s E,
      //   a = l.u, be = e.u, g = q.u, c = w.u, E = a g - l.q,
      //   s = ks (1 - l0/L) + kd c / L, each term as the definiteness fix clamps it.
      // Newton: phi = lambda^T (h f(x1, v1) - M (v1 - v0)) with v1 held, f_a = -(ks (L - l0)
      // + kd w.u) u per spring at x1 = x0 + h v1: exact (no definiteness fix).
      for (int sp = 0; newton && sp < springs.size(); ++sp) {
        const int ia = springs.a[sp], ib = springs.b[sp];
        const Vec3 d = particle(x1, ia) - particle(x1, ib);
        const Real length = d.norm();
        const Real l0 = rest[sp];
        if (!(length > kDegenerateLength * l0)) continue;  // collapsed: not differentiated
        const Real ks = springs.ks[sp], kd = springs.kd[sp];
        const Real inv = 1 / length;
        const Vec3 u = d * inv;
        const Vec3 l = particle(lambda, ia) - particle(lambda, ib);
        const Vec3 w = particle(v1, ia) - particle(v1, ib);
        const Real al = l.dot(u), c = w.dot(u);
        const Real magnitude = ks * (length - l0) + kd * c;
        const Vec3 grad_d =
            -h * ((ks * u + kd * (w - c * u) * inv) * al + magnitude * (l - al * u) * inv);
        particle(x0b, ia) += grad_d;
        particle(x0b, ib) -= grad_d;
        const size_t at = static_cast<size_t>(kSpringTypeCount) * spring_body[sp] +
                          static_cast<size_t>(springs.type[sp]);
        out.ks[at] -= h * (length - l0) * al;
        out.kd[at] -= h * c * al;
      }
      for (int sp = 0; !newton && sp < springs.size(); ++sp) {
        const int ia = springs.a[sp], ib = springs.b[sp];
        const Vec3 d = particle(r.x, ia) - particle(r.x, ib);
        const Real length = d.norm();
        const Real l0 = rest[sp];
        if (!(length > kDegenerateLength * l0)) continue;  // collapsed: not differentiated
        const Real ks = springs.ks[sp], kd = springs.kd[sp];
        const Real inv = 1 / length;
        const Vec3 u = d * inv;
        const Vec3 l = particle(lambda, ia) - particle(lambda, ib);
        const Vec3 e = particle(r.dv, ia) - particle(r.dv, ib);
        const Vec3 w = particle(r.v, ia) - particle(r.v, ib);
        const Vec3 q = w + e;
        const Real al = l.dot(u), be = e.dot(u), ga = q.dot(u), c = w.dot(u), lq = l.dot(q);
        const Real s1 = ks * (1 - l0 * inv), s2 = kd * c * inv;
        bool on1 = true, on2 = true;
        if (options.definiteness == DefinitenessFix::kClampCompressed) {
          on1 = s1 > 0;
          on2 = s2 > 0;
        } else if (options.definiteness == DefinitenessFix::kProjectPsd) {
          on1 = on2 = s1 + s2 > 0;
        }
        const Real s = (on1 ? s1 : 0) + (on2 ? s2 : 0);
        const Real big_e = al * ga - lq;
        const Vec3 pl = (l - al * u) * inv, pe = (e - be * u) * inv, pw = (w - c * u) * inv,
                   pq = (q - ga * u) * inv;
        Vec3 ds = Vec3::Zero();
        if (on1) ds += (ks * l0 * inv * inv) * u;
        if (on2) ds += (kd * inv) * (pw - c * inv * u);
        const Vec3 de = ga * pl + al * pq;
        const Vec3 grad_d = -ks * (al * u + (length - l0) * pl) -
                            kd * ((c + be) * pl + al * (pw + pe)) - h * ks * de +
                            h * (s * de + big_e * ds);
        Vec3 grad_w = -kd * al * u - h * ks * al * u + h * s * (al * u - l);
        if (on2) grad_w += (h * big_e * kd * inv) * u;
        const Real grad_ks =
            -(length - l0) * al - h * al * ga + (on1 ? h * big_e * (1 - l0 * inv) : 0);
        const Real grad_kd = -al * (c + be) + (on2 ? h * big_e * c * inv : 0);
        particle(x0b, ia) += h * grad_d;
        particle(x0b, ib) -= h * grad_d;
        particle(v0b, ia) += h * grad_w;
        particle(v0b, ib) -= h * grad_w;
        const size_t at = static_cast<size_t>(kSpringTypeCount) * spring_body[sp] +
                          static_cast<size_t>(springs.type[sp]);
        out.ks[at] += h * grad_ks;
        out.kd[at] += h * grad_kd;
      }
      // Contact pairs between bodies: phi gains Lambda . q(w1), Lambda = lambda_j - lambda_i,
      // with the impulse on j q(w1) = -(kappa m / h) g1 n - c P_t w1, g1 = gap0 + h n.w1,
      // w1 = v1_j - v1_i, n and gap0 from x0 (n = d / |d|, gap0 = |d| - reach, d = x_j0 - x_i0),
      // m = 1 / (w_i + w_j) from the masses, c = kappa m while the pair sticks (held while it
      // slides: the viscosity comes from the previous solve).
      for (const BodyPair& p : r.pairs) {
        const Vec3& nn = p.normal;
        const Vec3 lam = particle(lambda, p.j) - particle(lambda, p.i);
        const Vec3 w1 =
            particle(r.v, p.j) + particle(r.dv, p.j) - particle(r.v, p.i) - particle(r.dv, p.i);
        const Real km = p.kappa * p.mass;
        const Real c = p.slide ? p.viscosity : km;
        const Real al = lam.dot(nn), bn = nn.dot(w1), g1 = p.gap0 + h * bn;
        const Real tangential = lam.dot(w1) - al * bn;  // Lambda . P_t w1
        if (!newton) {                                  // (Newton: w1 is the unknown's)
          const Vec3 grad_w = -km * al * nn - c * (lam - al * nn);
          particle(v0b, p.j) += grad_w;
          particle(v0b, p.i) -= grad_w;
        }
        const Real length = (particle(r.x, p.j) - particle(r.x, p.i)).norm();
        const Vec3 grad_n = -(km / h) * (h * al * w1 + g1 * lam) + c * (bn * lam + al * w1);
        const Vec3 grad_d = (-(km / h) * al) * nn + (grad_n - nn.dot(grad_n) * nn) / length;
        particle(x0b, p.j) += grad_d;
        particle(x0b, p.i) -= grad_d;
        const Real grad_m = -(p.kappa / h) * g1 * al - (p.slide ? 0.0 : p.kappa * tangential);
        for (const int q : {p.i, p.j}) {
          const Real wq = inverse_mass[q];
          out.particle_mass[particle_body[q]] += grad_m * p.mass * p.mass * wq * wq;
        }
        if (p.slide && p.viscosity != 0)
          pending_pairs.push_back({p.i, p.j, -tangential, p.viscosity});
      }
      for (const Constraint& c : cons) slot[c.particle] = -1;
      xb.swap(x0b);
      vb.swap(v0b);
      if (loss.at(k)) {
        xb += loss.dx(k);
        vb += loss.dv(k);
      }
    }
  }
  for (const PendingViscosity& pv : pending)  // the first step's: set before the run
    if (pv.value != 0) ++out.slide_steps;
  out.pair_slide_steps += static_cast<long>(pending_pairs.size());
  if (end_of_run) sim.restore(std::move(*end_of_run));
  out.initial_position = xb;
  out.initial_velocity = vb;
  out.backward_seconds = seconds_since(start);
  return out;
}

}  // namespace jelly
