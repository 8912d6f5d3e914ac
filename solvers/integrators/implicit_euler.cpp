#include <jelly/solvers/integrators/detail/implicit_euler.hpp>

#include <chrono>
#include <cmath>
#include <optional>

#include <jelly/core/detail/clock.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/implicit_body_contact.hpp>
#include <jelly/solvers/contact/detail/implicit_contact.hpp>
#include <jelly/solvers/integrators/detail/assembled_system.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler_checkpoint.hpp>
#include <jelly/solvers/integrators/detail/matrix_free_system.hpp>

namespace jelly {

namespace {

// Below this many unknowns a fresh CHOLMOD factorization every step is cheap and exact; above
// it block-Jacobi CG was the fastest backend at every size and stiffness of the benchmark
// (docs/implicit.md, "Measured speed"; bench/implicit_benchmark.cpp).
constexpr int kAutoDirectMaxDofs = 1000;

// Uniform translations are in the null space of K and D, so 1^T A = 1^T M and an exact solve
// of A y = b changes the momentum by sum(b). An iterative solve misses by the sum of its
// residual; this shifts y uniformly (which changes nothing else) to restore that identity.
void restore_momentum(const VecX& mass, const VecX& b, VecX& y) {
  const Eigen::Index np = mass.size();
  Vec3 missing = Vec3::Zero();
  for (Eigen::Index i = 0; i < np; ++i)
    missing += b.segment<3>(3 * i) - mass[i] * y.segment<3>(3 * i);
  const Vec3 shift = missing / mass.sum();
  for (Eigen::Index i = 0; i < np; ++i) y.segment<3>(3 * i) += shift;
}

// body(k) for every entry k of a vector of 3 entries per particle, split between up to `threads`
// threads at particles, as the particle loops are (each entry's arithmetic is its own: the same
// bits for any split).
template <class Body>
void for_each_entry(int threads, Eigen::Index n, Body&& body) {
  parallel::for_ranges(
      threads, static_cast<long>(n),
      [&](long begin, long end) {
        for (long k = begin; k < end; ++k) body(k);
      },
      parallel::kMinItemsPerThread, 3);
}

}  // namespace

ImplicitLinearSolver auto_linear_solver(int dofs) {
  return dofs <= kAutoDirectMaxDofs ? ImplicitLinearSolver::kCholmod : ImplicitLinearSolver::kCg;
}

struct ImplicitEuler::Impl {
  explicit Impl(ImplicitEulerOptions o) : options_(std::move(o)), matrix_free_(options_, times_) {}

  bool resolves_contact() const {
    return options_.contact == ImplicitContactMode::kImplicit && terrains_seen_;
  }
  bool resolves_body_contact() const {
    return options_.contact == ImplicitContactMode::kImplicit && bodies_seen_;
  }
  void add_statistics(Statistics& s) const;
  StepResult step(const Dynamics& dynamics, State& state, Real h);
  // The system of this step: matrix-free where it can be, else assembled (built anew only when
  // the model's springs or the kind changed).
  StepResult prepare(const Dynamics& dynamics, Real h);
  // The added forces' Jacobians (assembled system) and A at (x, v): the system's assembly, and
  // wind drag; a matrix-free system that meets a collapsed spring hands over to an assembled one.
  StepResult assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real t, Real h);
  // Solves A y = b with the step's system (constrained: filtered by the contacts) to CG's
  // `cg_tolerance` (0: options_.cg_tolerance); `resume`: continues the last loose solve.
  StepResult factorize_and_solve(const Model& model, const VecX& b, VecX& y, bool constrained,
                                 Real t, Real cg_tolerance = 0, bool resume = false);
  // The solve's status as a step result (naming t), a check for non-finite values, and the
  // momentum correction of an unconstrained CG solve.
  StepResult finish_solve(const Model& model, const LinearResult& r, const VecX& b, VecX& y,
                          bool constrained, Real t);
  // Factorizes A (filtered by the contact constraints, if any) and solves for dv_: the
  // linearized step, repeated while the contacts' active set changes.
  StepResult linearized_solve(const Dynamics& dynamics, const State& s, Real h);
  // solved_constraints_ = the contact set about to be solved (empty when unconstrained).
  void record_constraints(bool constrained, const Terrains& terrains);
  // solved_pairs_ = the active pairs between bodies whose terms the system holds.
  void record_pairs();
  // Newton corrections on the nonlinear backward-Euler equations from v1_.
  StepResult newton(const Dynamics& dynamics, const State& s, Real h);
  // Wind drag at time t: d(f)/d(v) = -drag on its particles, so A gains h drag on the diagonal
  // (and 1^T A = 1^T M no longer holds: damped_ says so).
  void add_external_damping_system(const Model& model, Real t, Real h);
  // The assembled system when it is the step's (contact pairs between bodies and added forces'
  // Jacobians need it), else null.
  AssembledSystem* assembled() {
    return assembled_ && system_ == &*assembled_ ? &*assembled_ : nullptr;
  }

  ImplicitEulerOptions options_;
  SystemTimes times_;
  // The step's system (one of the two below); null before the first step.
  BackwardEulerSystem* system_ = nullptr;
  std::optional<AssembledSystem> assembled_;
  // Kept when the assembled system takes over (its counters are the run's).
  MatrixFreeSystem matrix_free_;
  bool matrix_free_failed_ = false;  // a collapsed spring: the assembled system from then on
  int threads_ = 1;
  VecX f_, kw_, b_, dv_, v1_, x1_, g_, delta_, rhs_, z_, damping_;
  ImplicitContact contact_;
  ImplicitBodyContact bodies_;
  BodyContact* body_contact_ = nullptr;         // of the current step (null: none, or after_step)
  bool bodies_active_ = false;                  // the current step has candidate pairs
  bool bodies_seen_ = false;                    // the last step's Dynamics had body contact
  const Terrains* contact_terrains_ = nullptr;  // the terrains contact_ resolves this step
  bool contact_active_ = false;                 // the current step constrains contacts
  bool terrains_seen_ = true;                   // the last step's Dynamics had terrains
  // The current step's A has terms off the springs' (anchors, forces' Jacobians, wind drag),
  // which break 1^T A = 1^T M.
  bool anchored_ = false;
  bool damped_ = false;  // the last assembly added wind drag
  Real last_h_ = 0;
  bool have_dv_ = false;
  std::vector<Real> residuals_;
  // The constraints of the last solve of the step (for the adjoint).
  std::vector<ImplicitEuler::SolvedConstraint> solved_constraints_;
  // The active contact pairs between bodies whose terms the step's last solve held (for the
  // adjoint).
  std::vector<ImplicitEuler::SolvedPair> solved_pairs_;
  bool converged_ = true;
  long newton_iterations_ = 0;
  long newton_not_converged_ = 0;
};

ImplicitEuler::ImplicitEuler(ImplicitEulerOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {
  impl_->options_.validate("ImplicitEulerOptions.");
  impl_->residuals_.reserve(impl_->options_.newton_iterations + 1);
}

ImplicitEuler::~ImplicitEuler() = default;

const ImplicitEulerOptions& ImplicitEuler::options() const { return impl_->options_; }

const std::vector<Real>& ImplicitEuler::last_residuals() const { return impl_->residuals_; }

bool ImplicitEuler::last_converged() const { return impl_->converged_; }

const std::vector<ImplicitEuler::SolvedConstraint>& ImplicitEuler::last_constraints() const {
  return impl_->solved_constraints_;
}

const VecX& ImplicitEuler::last_velocity_change() const { return impl_->dv_; }

bool ImplicitEuler::last_step_had_body_contact() const { return impl_->bodies_active_; }

const std::vector<ImplicitEuler::SolvedPair>& ImplicitEuler::last_pairs() const {
  return impl_->solved_pairs_;
}

std::string_view ImplicitEuler::linear_solver_name() const {
  return impl_->system_ != nullptr ? impl_->system_->name() : std::string_view();
}

Statistics ImplicitEuler::statistics() const {
  Statistics s = Integrator::statistics();
  impl_->add_statistics(s);
  return s;
}

StepResult ImplicitEuler::do_step(const Dynamics& dynamics, State& s, Real h) {
  return impl_->step(dynamics, s, h);
}

std::vector<ToleranceMiss> ImplicitEuler::tolerance_misses() const {
  const ImplicitEulerOptions& o = impl_->options_;
  if (o.newton_iterations <= 1) return {};
  return {
      {"implicit_euler: Newton did not converge within integrator.options.newton_iterations = " +
           std::to_string(o.newton_iterations) +
           " (newton_tolerance = " + tolerance_text(o.newton_tolerance) + ")",
       impl_->newton_not_converged_}};
}

void ImplicitEuler::Impl::add_statistics(Statistics& s) const {
  LinearSolverCounters c = assembled_ ? assembled_->counters() : LinearSolverCounters{};
  const LinearSolverCounters& mf = matrix_free_.counters();
  c.solves += mf.solves;
  c.cg_iterations += mf.cg_iterations;
  s["symbolic_analyses"] = static_cast<double>(c.analyses);
  s["numeric_factorizations"] = static_cast<double>(c.factorizations);
  s["linear_solves"] = static_cast<double>(c.solves);
  s["cg_iterations"] = static_cast<double>(c.cg_iterations);
  s["newton_iterations"] = static_cast<double>(newton_iterations_);
  s["newton_not_converged"] = static_cast<double>(newton_not_converged_);
  s["assembly_seconds"] = times_.assembly;
  s["factorization_seconds"] = times_.factorization;
  s["solve_seconds"] = times_.solve;
  if (matrix_free_.uses_multigrid())
    s["multigrid_levels"] = static_cast<double>(matrix_free_.multigrid_levels());
  if (assembled_ && assembled_->multigrid_levels() > 0) {  // cg_preconditioner = amg
    s["multigrid_levels"] = static_cast<double>(assembled_->multigrid_levels());
    s["amg_refreshes"] = static_cast<double>(assembled_->preconditioner_refreshes());
  }
  if (resolves_contact()) {
    const ImplicitContact::Counters& cc = contact_.counters();
    s["contact_extra_solves"] = static_cast<double>(cc.extra_solves);
    s["contact_not_converged"] = static_cast<double>(cc.not_converged);
    s["contact_restitution_limited"] = static_cast<double>(cc.restitution_limited);
  }
  if (resolves_body_contact()) {
    const ImplicitBodyContact::Counters& bc = bodies_.counters();
    s["body_contact_extra_solves"] = static_cast<double>(bc.extra_solves);
    s["body_contact_not_converged"] = static_cast<double>(bc.not_converged);
    s["body_contact_restitution_limited"] = static_cast<double>(bc.restitution_limited);
    s["body_contact_projected"] = static_cast<double>(bc.projected);
  }
}

std::vector<Real> ImplicitEuler::internal_state() const {
  const Impl& m = *impl_;
  ImplicitEulerCheckpoint c;
  if (m.have_dv_) c.warm_start = m.dv_;
  if (m.bodies_.saved_size() > 0) m.bodies_.save(c.body_pairs);
  m.contact_.save(c.contact_set);
  return c.to_numbers();
}

void ImplicitEuler::restore_internal_state(const std::vector<Real>& data) {
  Impl& m = *impl_;
  m.matrix_free_.mark_coarse_stale();  // multigrid: rebuilt from the restored state
  const ImplicitEulerCheckpoint c = ImplicitEulerCheckpoint::from_numbers(data);
  // A warm start of another size (another model) is dropped; prepare() sizes dv_ then.
  const int rows = m.system_ != nullptr ? m.system_->rows() : -1;
  const Eigen::Index size = c.warm_start.size();
  m.have_dv_ = size > 0 && (rows < 0 || size == rows);
  if (m.have_dv_) m.dv_ = c.warm_start;
  m.bodies_.restore(c.body_pairs.data(), c.body_pairs.size());
  m.contact_.restore(c.contact_set.data(), c.contact_set.size());
}

StepResult ImplicitEuler::Impl::prepare(const Dynamics& dynamics, Real h) {
  const Model& model = dynamics.model();
  const int n = model.num_dofs();
  const bool automatic = options_.linear_solver == ImplicitLinearSolver::kAuto;
  const ImplicitLinearSolver kind = automatic ? auto_linear_solver(n) : options_.linear_solver;
  const SpringBands* bands = dynamics.bands();
  // Block-Jacobi CG needs only products with A: from the bands when the springs fill them.
  const bool matrix_free =
      kind == ImplicitLinearSolver::kCg &&
      (automatic || options_.cg_preconditioner != CgPreconditionerKind::kCholmod) &&
      options_.cg_preconditioner != CgPreconditionerKind::kAmg &&  // on the assembled matrix
      bands != nullptr && bands->dense() && bands->fits(model) && !matrix_free_failed_ &&
      // Contact pairs between bodies add blocks off the springs' bands: the assembled matrix.
      !(options_.contact == ImplicitContactMode::kImplicit && dynamics.body_contact() != nullptr);
  const auto size_vectors = [&] {
    for (VecX* w : {&f_, &kw_, &b_, &v1_, &x1_, &g_, &delta_, &rhs_, &z_})
      if (w->size() != n) w->setZero(n);
    if (dv_.size() != n) {  // (a restored warm start of the right size stays)
      dv_.setZero(n);
      have_dv_ = false;
    }
  };
  if (matrix_free) {
    if (system_ != &matrix_free_ || !matrix_free_.built_for(*bands, n)) {
      const auto start = Clock::now();
      assembled_.reset();
      matrix_free_.build(model, *bands);
      size_vectors();
      system_ = &matrix_free_;
      times_.factorization += seconds_since(start);
    }
  } else if (assembled() == nullptr || !assembled_->fits(model)) {
    const auto start = Clock::now();
    matrix_free_.release();
    system_ = nullptr;
    assembled_.emplace(model, kind, automatic, options_, times_);
    const StepResult r = assembled_->analyze();
    times_.factorization += seconds_since(start);
    if (!r.ok) return r;
    system_ = &*assembled_;
    size_vectors();
  }
  if (h != last_h_) system_->invalidate();
  last_h_ = h;
  return StepResult::success();
}

void ImplicitEuler::Impl::add_external_damping_system(const Model& model, Real t, Real h) {
  damped_ = false;
  if (model.external_forces.empty()) return;
  ensure_size(damping_, model.num_particles());
  damping_.setZero();
  add_external_damping(model.external_forces, t, damping_);
  for (int i = 0; i < model.num_particles(); ++i) {
    if (damping_[i] == 0) continue;
    damped_ = true;
    system_->add_diagonal(i, h * damping_[i]);
  }
}

StepResult ImplicitEuler::Impl::assemble(const Dynamics& dynamics, const VecX& x, const VecX& v,
                                         Real t, Real h) {
  if (StepResult r = system_->collect_force_jacobians(dynamics, x, v, t); !r.ok) return r;
  if (!system_->assemble(dynamics, x, v, h, kw_)) {
    // A collapsed spring in the matrix-free system: the assembled system from then on.
    matrix_free_failed_ = true;
    if (StepResult r = prepare(dynamics, h); !r.ok) return r;
    system_->set_threads(threads_);
    if (StepResult r = system_->collect_force_jacobians(dynamics, x, v, t); !r.ok) return r;
    system_->assemble(dynamics, x, v, h, kw_);
  }
  add_external_damping_system(dynamics.model(), t, h);
  return StepResult::success();
}

StepResult ImplicitEuler::Impl::factorize_and_solve(const Model& model, const VecX& b, VecX& y,
                                                    bool constrained, Real t, Real cg_tolerance,
                                                    bool resume) {
  const LinearResult r =
      system_->solve(b, y, constrained ? &contact_ : nullptr,
                     cg_tolerance > 0 ? cg_tolerance : options_.cg_tolerance, resume);
  return finish_solve(model, r, b, y, constrained, t);
}

StepResult ImplicitEuler::Impl::finish_solve(const Model& model, const LinearResult& r,
                                             const VecX& b, VecX& y, bool constrained, Real t) {
  if (!r.ok())
    return StepResult::failure("implicit_euler: linear solve failed at t = " + to_text(t) + " (" +
                               std::string(linear_status_name(r.status)) + "): " + r.message);
  if (!y.allFinite())
    return StepResult::failure("implicit_euler: the linear solve returned a non-finite value");
  // With contact constraints, anchors or added forces momentum is not conserved (the terrain,
  // the anchor or the force pushes).
  if (r.iterations > 0 && !constrained && !anchored_) restore_momentum(model.mass, b, y);
  return StepResult::success();
}

void ImplicitEuler::Impl::record_constraints(bool constrained, const Terrains& terrains) {
  solved_constraints_.clear();
  if (!constrained) return;
  using Kind = ImplicitEuler::SolvedConstraint::Kind;
  for (const ImplicitContact::Contact& c : contact_.contacts()) {
    ImplicitEuler::SolvedConstraint r;
    r.particle = c.particle;
    if (c.pinned) {
      r.kind = Kind::kPin;
    } else {
      r.kind = c.mode == ImplicitContact::Mode::kSlide ? Kind::kSlide : Kind::kStick;
      r.normal = c.normal;
      r.surface_velocity = c.surface_velocity;
      r.viscosity = r.kind == Kind::kSlide ? c.viscosity : 0.0;
      const ContactParams& params = terrains[c.terrain]->contact();
      r.bounces = params.restitution > 0 && c.approach > params.resting_speed;
      r.friction = params.friction;
      r.static_friction = params.static_friction;
    }
    solved_constraints_.push_back(r);
  }
}

void ImplicitEuler::Impl::record_pairs() {
  solved_pairs_.clear();
  if (!bodies_active_) return;
  for (const ImplicitBodyContact::Pair& p : bodies_.pairs()) {
    if (!p.active) continue;
    ImplicitEuler::SolvedPair r;
    r.i = p.i;
    r.j = p.j;
    r.normal = p.normal;
    r.gap0 = p.gap0;
    r.mass = p.mass;
    r.approach = p.approach;
    r.kappa = p.kappa;
    r.slide = p.mode == ImplicitBodyContact::Mode::kSlide;
    r.viscosity = r.slide ? p.viscosity : 0.0;
    solved_pairs_.push_back(r);
  }
}

StepResult ImplicitEuler::Impl::linearized_solve(const Dynamics& dynamics, const State& s, Real h) {
  const Model& model = dynamics.model();
  const int np = model.num_particles();
  const Real* m = model.mass.data();
  // (M - h D - h^2 K) dv = h (f + h K v); K v comes out of the assembly.
  const auto start = Clock::now();
  dynamics.forces(s.t + h, s.x, s.v, f_);
  if (!have_dv_) {  // first guess for CG: the explicit step h M^-1 f; later the last dv
    for (int i = 0; i < np; ++i) dv_.segment<3>(3 * i) = (h / m[i]) * f_.segment<3>(3 * i);
  }
  // Contact between bodies: the candidate pairs, and their blocks in the pattern.
  body_contact_ =
      options_.contact == ImplicitContactMode::kImplicit ? dynamics.body_contact() : nullptr;
  bodies_seen_ = body_contact_ != nullptr;
  bodies_active_ = body_contact_ != nullptr && bodies_.begin_step(model, *body_contact_, s, f_, h);
  if (assembled_) assembled_->forget_saved_assembly();
  if (bodies_active_) {
    if (StepResult r = assembled_->ensure_pairs(model, bodies_.pairs()); !r.ok) return r;
  }
  if (StepResult r = assemble(dynamics, s.x, s.v, s.t + h, h); !r.ok) return r;
  anchored_ = dynamics.anchors() != nullptr || system_->has_force_terms() || damped_;
  b_.resize(f_.size());
  for_each_entry(threads_, b_.size(), [&](long k) { b_[k] = h * (f_[k] + h * kw_[k]); });
  if (bodies_active_ && bodies_.any_active()) assembled_->refresh_pair_terms(bodies_, b_);
  record_pairs();
  times_.assembly += seconds_since(start);
  terrains_seen_ = dynamics.terrains() != nullptr;
  // The terrains whose contact this solve resolves (none with contact = "after_step"); pinned
  // particles are constraints of the solve either way.
  static const Terrains kNoTerrains;
  const Terrains* terrains = resolves_contact() ? dynamics.terrains() : &kNoTerrains;
  contact_terrains_ = terrains;
  contact_active_ = (resolves_contact() || !model.pins.empty()) &&
                    contact_.begin_step(model, *terrains, s, f_, h, threads_);
  // One solve of the current set (constrained by the contacts it holds) into dv_, to CG's
  // `tolerance` (0: cg_tolerance); `resume`: the set and the system are the last solve's, whose
  // CG iteration this one continues (rhs_, z_ and the block inverses stay).
  const auto solve = [&](Real tolerance, bool resume) -> StepResult {
    const bool constrained = contact_active_ && contact_.has_constraints();
    if (!resume) record_constraints(constrained, *terrains);
    if (constrained && !resume) system_->constrain(contact_, b_, true, rhs_, z_, dv_);
    StepResult r = factorize_and_solve(model, constrained ? rhs_ : b_, dv_, constrained, s.t,
                                       tolerance, resume);
    if (!r.ok) {
      have_dv_ = false;
      return r;
    }
    if (constrained) for_each_entry(threads_, dv_.size(), [&](long k) { dv_[k] += z_[k]; });
    return r;
  };
  // Solve; with contacts, again while their active set changes.
  for (int round = 1;; ++round) {
    const bool constrained = contact_active_ && contact_.has_constraints();
    // Screening (options_.contact_screening_tolerance): a loose solve first, finished below
    // only if it keeps the contacts' set.
    const Real screen = options_.contact_screening_tolerance;
    const bool screening = system_ == &matrix_free_ && contact_active_ && !bodies_active_ &&
                           screen > options_.cg_tolerance && round < options_.contact_iterations;
    if (StepResult r = solve(screening ? screen : 0, false); !r.ok) return r;
    ++newton_iterations_;
    if (!contact_active_ && !bodies_active_) break;
    const bool last = round >= options_.contact_iterations;
    bool terrain_changed =
        contact_active_ && system_->update_contacts(contact_, *terrains, b_, dv_, !last, screening);
    if (screening && !terrain_changed) {
      // The set held on the loose solve: finish the solve at the full tolerance and check again.
      if (StepResult r = solve(0, true); !r.ok) return r;
      terrain_changed = system_->update_contacts(contact_, *terrains, b_, dv_, !last, false);
    }
    const bool pairs_changed = bodies_active_ && bodies_.update(dv_, !last);
    if (last || (!terrain_changed && !pairs_changed)) break;
    if (pairs_changed) {
      // The terrains' filter is undone (update() did it if their set changed) before the
      // pairs' terms change.
      if (constrained && !terrain_changed) assembled_->unconstrain(contact_);
      assembled_->refresh_pair_terms(bodies_, b_);
      record_pairs();
    }
  }
  have_dv_ = true;
  // The impulses the final solve's update found (same particles in the same order, or the
  // solved set kept when the set was still changing at the last solve).
  size_t j = 0;
  for (const ImplicitContact::Contact& c : contact_.contacts()) {
    while (j < solved_constraints_.size() && solved_constraints_[j].particle != c.particle) ++j;
    if (j == solved_constraints_.size()) break;
    solved_constraints_[j++].impulse = c.impulse;
  }
  return StepResult::success();
}

StepResult ImplicitEuler::Impl::newton(const Dynamics& dynamics, const State& s, Real h) {
  // Newton on g(v1) = M (v1 - v0) - h f(x0 + h v1, v1) = 0, dg/dv1 = M - h D - h^2 K; with
  // contacts, g is projected onto the free directions (the constraints hold already) and the
  // sliding friction impulses are part of it.
  const Model& model = dynamics.model();
  const int np = model.num_particles();
  const Real* m = model.mass.data();
  Real scale = h * f_.norm();
  if (!(scale > 0)) scale = 1;
  const bool constrained = contact_active_ && contact_.has_constraints();
  converged_ = false;
  // The constraints and pairs of every Newton iterate (their friction as last updated).
  record_constraints(constrained, *contact_terrains_);
  record_pairs();
  for (int k = 1;; ++k) {
    x1_ = s.x + h * v1_;
    dynamics.forces(s.t + h, x1_, v1_, f_);
    for (int i = 0; i < np; ++i)
      g_.segment<3>(3 * i) =
          m[i] * (v1_.segment<3>(3 * i) - s.v.segment<3>(3 * i)) - h * f_.segment<3>(3 * i);
    if (bodies_active_) bodies_.subtract_impulses(v1_, g_);
    if (constrained) {
      contact_.subtract_friction(v1_, g_);
      contact_.project(g_);
    }
    const Real residual = g_.norm();
    residuals_.push_back(residual);
    if (!std::isfinite(residual))
      return StepResult::failure("implicit_euler: Newton residual is not finite");
    if (residual <= options_.newton_tolerance * scale) {
      converged_ = true;
      break;
    }
    if (k >= options_.newton_iterations) break;
    g_ = -g_;
    delta_.setZero();
    const auto start = Clock::now();
    if (StepResult r = assemble(dynamics, x1_, v1_, s.t + h, h); !r.ok) return r;
    if (bodies_active_) assembled_->add_pair_terms(bodies_);
    times_.assembly += seconds_since(start);
    if (constrained) system_->constrain(contact_, g_, false, rhs_, z_, delta_);
    if (StepResult r =
            factorize_and_solve(model, constrained ? rhs_ : g_, delta_, constrained, s.t);
        !r.ok)
      return r;
    ++newton_iterations_;
    v1_ += delta_;
  }
  if (!converged_) ++newton_not_converged_;
  dv_ = v1_ - s.v;
  return StepResult::success();
}

StepResult ImplicitEuler::Impl::step(const Dynamics& dynamics, State& s, Real h) {
  threads_ = dynamics.threads();
  if (StepResult r = prepare(dynamics, h); !r.ok) return r;
  system_->set_threads(threads_);
  if (StepResult r = linearized_solve(dynamics, s, h); !r.ok) return r;
  v1_.resize(s.v.size());
  for_each_entry(threads_, v1_.size(), [&](long k) { v1_[k] = s.v[k] + dv_[k]; });
  residuals_.clear();
  converged_ = true;
  if (options_.newton_iterations > 1) {
    if (StepResult r = newton(dynamics, s, h); !r.ok) return r;
  }
  for_each_entry(threads_, v1_.size(), [&](long k) {
    s.v[k] = v1_[k];
    s.x[k] += h * s.v[k];
  });
  s.t += h;
  if (contact_active_) contact_.finish(dynamics.model(), *contact_terrains_, s, threads_);
  if (bodies_active_) {
    bodies_.finish(dynamics.model(), s, *body_contact_, threads_);
  } else if (body_contact_ != nullptr) {
    body_contact_->record_step({}, 0.0);
  }
  StepResult result = StepResult::success();
  result.contact = {resolves_contact(), resolves_body_contact(),
                    contact_active_ ? contact_.count() : 0};
  return result;
}

}  // namespace jelly
