#include <jelly/solvers/integrators/implicit_euler.hpp>

#include <chrono>
#include <cmath>
#include <optional>

#include <jelly/core/detail/anchor_jacobian.hpp>
#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/clock.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/contact/body_contact.hpp>
#include <jelly/solvers/contact/detail/implicit_body_contact.hpp>
#include <jelly/solvers/contact/detail/implicit_contact.hpp>
#include <jelly/solvers/linear/cg_solver.hpp>
#include <jelly/solvers/linear/cholmod_solver.hpp>
#include <jelly/solvers/linear/detail/lattice_multigrid.hpp>
#include <jelly/solvers/linear/ldlt_solver.hpp>

namespace jelly {

namespace {

// Below this many unknowns a fresh CHOLMOD factorization every step is cheap and exact; above
// it block-Jacobi CG was the fastest backend at every size and stiffness of the benchmark
// (docs/implicit.md, "Measured speed"; bench/implicit_benchmark.cpp).
constexpr int kAutoDirectMaxDofs = 1000;

// At cg_tolerance at or above this the matrix-free system keeps its two coefficients per spring
// in single precision (BandSystem): A is then exact to 6e-8 relative per spring, 1/16 of this,
// and the products read half the bytes (docs/implicit.md, "Matrix-free CG on lattices").
constexpr Real kSingleCoefficientsTolerance = 1e-6;

// Multigrid: the coarse operators (Galerkin products, many fine products' worth of work) are
// rebuilt every this many assemblies, and sooner when the contacts' set changes, when dt
// changes, or when a solve needs more than twice the iterations of the first solve with them
// (docs/implicit.md, "Multigrid on lattices"). Whatever coarse operators it holds, the V-cycle
// is symmetric positive definite.
constexpr int kMultigridMaxAge = 5;

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

// Whether a matrix of dense 3x3 blocks (full storage, sorted rows) holds block (i, j).
bool has_block(const SparseMatrix& a, int i, int j) {
  const int* outer = a.outerIndexPtr();
  const int* rows = a.innerIndexPtr();
  return std::binary_search(rows + outer[3 * j], rows + outer[3 * j + 1], 3 * i);
}

// a(i, j) += b for a dense 3x3 block (i, j) of a matrix of such blocks (full storage, sorted
// rows) that holds it.
void add_block(SparseMatrix& a, int i, int j, const Mat3& b) {
  const int* outer = a.outerIndexPtr();
  const int* rows = a.innerIndexPtr();
  Real* values = a.valuePtr();
  for (int c = 0; c < 3; ++c) {
    const int col = 3 * j + c;
    const int* at = std::lower_bound(rows + outer[col], rows + outer[col + 1], 3 * i);
    Real* v = values + (at - rows);
    for (int r = 0; r < 3; ++r) v[r] += b(r, c);
  }
}

// True when an added force gives its Jacobians.
bool has_force_jacobians(const Dynamics& dynamics) {
  const ForceList* forces = dynamics.added_forces();
  if (forces == nullptr) return false;
  return std::any_of(forces->begin(), forces->end(),
                     [](const std::shared_ptr<Force>& f) { return f->has_jacobian(); });
}

}  // namespace

ImplicitLinearSolver auto_linear_solver(int dofs) {
  return dofs <= kAutoDirectMaxDofs ? ImplicitLinearSolver::kCholmod : ImplicitLinearSolver::kCg;
}

struct ImplicitEuler::Impl {
  explicit Impl(ImplicitEulerOptions o) : options_(std::move(o)) {}

  bool resolves_contact() const {
    return options_.contact == ImplicitContactMode::kImplicit && terrains_seen_;
  }
  bool resolves_body_contact() const {
    return options_.contact == ImplicitContactMode::kImplicit && bodies_seen_;
  }
  // Makes the matrix pattern hold the blocks of every candidate pair of bodies_ (the union of
  // the candidates seen so far; a new symbolic analysis only when a pair is new).
  StepResult ensure_pattern(const Model& model);
  // a_ and b_ = the saved assembly plus the active pairs' terms (saves the assembly first).
  void refresh_pair_terms();
  void add_statistics(Statistics& s) const;
  StepResult step(const Dynamics& dynamics, State& state, Real h);
  StepResult prepare(const Dynamics& dynamics, Real h);
  // The added forces' Jacobian blocks at (t, x, v) into force_jacobian_, and their blocks in
  // the matrix pattern (a new symbolic analysis only when a block is new).
  StepResult collect_force_jacobians(const Dynamics& dynamics, const VecX& x, const VecX& v,
                                     Real t);
  // The pattern of a_: the springs' blocks, the contact pairs' and the forces' (extra_blocks_
  // and force_blocks_); analysed again.
  StepResult rebuild_pattern(const Model& model);
  // A = M - h D - h^2 K (+ anchors, wind drag) and kw_ = K w at (x, v), into a_ or band_.
  StepResult assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real t, Real h);
  // The contact filter of the system and its right-hand side (constrain() of ImplicitContact,
  // or its matrix-free counterpart).
  void constrain(const VecX& b, bool prescribe, VecX& guess);
  // The contacts' next active set after a solve (ImplicitContact::update).
  bool update_contacts(const Terrains& terrains, const VecX& b, bool commit,
                       bool screening = false);
  // Matrix-free block-Jacobi CG on band_ (filtered by the contacts when constrained), to the
  // relative residual `tolerance`; `resume`: continues the last solve's CG iteration (the same
  // system and block inverses) to this tolerance.
  StepResult solve_matrix_free(const Model& model, const VecX& b, VecX& y, bool constrained, Real t,
                               Real tolerance, bool resume);
  // The solve's status as a step result (naming t), a check for non-finite values, and the
  // momentum correction of an unconstrained CG solve.
  StepResult finish_solve(const Model& model, const LinearResult& r, const VecX& b, VecX& y,
                          bool constrained, Real t);
  // Factorizes A (filtered by the contact constraints, if any) and solves for dv_: the
  // linearized step, repeated while the contacts' active set changes.
  StepResult linearized_solve(const Dynamics& dynamics, const State& s, Real h);
  // Factorizes a_ and solves a_ y = b (constrained: a_ is filtered by contacts); a matrix-free
  // solve to `cg_tolerance` when given (a screening solve), else to options_.cg_tolerance, and
  // with `resume` (matrix-free only) from the last solve's system and preconditioner.
  StepResult factorize_and_solve(const Model& model, const VecX& b, VecX& y, bool constrained,
                                 Real t, Real cg_tolerance = 0, bool resume = false);
  // solved_constraints_ = the contact set about to be solved (empty when unconstrained).
  void record_constraints(bool constrained, const Terrains& terrains) {
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
  // Newton corrections on the nonlinear backward-Euler equations from v1_.
  StepResult newton(const Dynamics& dynamics, const State& s, Real h);
  // Wind drag at time t: d(f)/d(v) = -drag on its particles, so A gains h drag on the diagonal
  // (and 1^T A = 1^T M no longer holds: damped_ says so).
  void add_external_damping_system(const Model& model, Real t, Real h) {
    damped_ = false;
    if (model.external_forces.empty()) return;
    ensure_size(damping_, model.num_particles());
    damping_.setZero();
    add_external_damping(model.external_forces, t, damping_);
    for (int i = 0; i < model.num_particles(); ++i) {
      if (damping_[i] == 0) continue;
      damped_ = true;
      if (matrix_free_) {
        band_->add_diagonal(i, h * damping_[i]);
      } else {
        for (int d = 0; d < 3; ++d) jacobian_->add_to_diagonal(a_, 3 * i + d, h * damping_[i]);
      }
    }
  }

  ImplicitEulerOptions options_;
  JacobianOptions jacobian_options_;
  std::optional<SpringJacobian> jacobian_;
  std::unique_ptr<LinearSolver> solver_;
  SparseMatrix a_;
  // Matrix-free path (auto and block-Jacobi CG on a lattice whose springs fill the force loop's
  // bands): no sparse matrix, A's blocks per spring (core/detail/band_system.hpp).
  bool matrix_free_ = false;
  bool matrix_free_failed_ = false;  // a collapsed spring: the assembled path from then on
  std::optional<BandSystem> band_;
  MatrixFreeCg band_cg_;
  // cg_preconditioner = multigrid on the matrix-free path, when the model has a lattice body:
  // the V-cycle, and whether its coarse operators are older than the last assembly.
  LatticeMultigrid multigrid_;
  bool use_multigrid_ = false;
  bool coarse_stale_ = true;
  int coarse_age_ = 0;          // assemblies since the coarse operators were built
  int coarse_iterations_ = -1;  // CG iterations of the first solve with them (-1: none yet)
  // The contacts (particle, stick or slide) the coarse operators were built with: those of
  // another set are far from its operator (a released contact's coupling is missing from them,
  // and a solve needed up to 87 iterations instead of 6), so a solve with another set rebuilds
  // them.
  std::vector<std::pair<int, int>> coarse_contacts_, contacts_now_;
  VecX az_;
  VecX cg_x_;                      // a loose matrix-free solve's iterate, for resuming it
  int loose_iterations_ = 0;       // ... and its CG iterations
  std::vector<int> contact_rows_;  // the contacts' particles, for their rows of A dv
  int threads_ = 1;
  VecX f_, kw_, b_, dv_, v1_, x1_, g_, delta_, rhs_, z_, damping_;
  ImplicitContact contact_;
  ImplicitBodyContact bodies_;
  BodyContact* body_contact_ = nullptr;  // of the current step (null: none, or after_step)
  bool bodies_active_ = false;           // the current step has candidate pairs
  bool bodies_seen_ = false;             // the last step's Dynamics had body contact
  bool base_saved_ = false;              // base_values_ / b_base_ hold this step's assembly
  std::vector<std::pair<int, int>> extra_blocks_;  // pair blocks in jacobian_'s pattern
  ForceJacobian force_jacobian_;                   // the added forces' blocks of this assembly
  std::vector<std::pair<int, int>> force_blocks_;  // their off-diagonal blocks in the pattern
  std::vector<Real> base_values_;
  VecX b_base_;
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
  bool converged_ = true;
  long newton_iterations_ = 0;
  long newton_not_converged_ = 0;
  double assembly_seconds_ = 0, factorization_seconds_ = 0, solve_seconds_ = 0;
};

ImplicitEuler::ImplicitEuler(ImplicitEulerOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {
  impl_->options_.validate("ImplicitEulerOptions.");
  impl_->jacobian_options_.definiteness = impl_->options_.definiteness;
  impl_->residuals_.reserve(impl_->options_.newton_iterations + 1);
}

ImplicitEuler::~ImplicitEuler() = default;

bool ImplicitEuler::resolves_contact() const { return impl_->resolves_contact(); }

bool ImplicitEuler::resolves_body_contact() const { return impl_->resolves_body_contact(); }

int ImplicitEuler::contacts_resolved() const {
  return impl_->contact_active_ ? impl_->contact_.count() : 0;
}

const ImplicitEulerOptions& ImplicitEuler::options() const { return impl_->options_; }

const std::vector<Real>& ImplicitEuler::last_residuals() const { return impl_->residuals_; }

bool ImplicitEuler::last_converged() const { return impl_->converged_; }

const std::vector<ImplicitEuler::SolvedConstraint>& ImplicitEuler::last_constraints() const {
  return impl_->solved_constraints_;
}

const VecX& ImplicitEuler::last_velocity_change() const { return impl_->dv_; }

bool ImplicitEuler::last_step_had_body_contact() const { return impl_->bodies_active_; }

std::string_view ImplicitEuler::linear_solver_name() const {
  if (impl_->matrix_free_)
    return impl_->use_multigrid_ ? "cg_multigrid_matrix_free" : "cg_jacobi_matrix_free";
  return impl_->solver_ ? impl_->solver_->name() : std::string_view();
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
  LinearSolverCounters c = solver_ ? solver_->counters() : LinearSolverCounters{};
  const LinearSolverCounters& mf = band_cg_.counters();
  c.solves += mf.solves;
  c.cg_iterations += mf.cg_iterations;
  s["symbolic_analyses"] = static_cast<double>(c.analyses);
  s["numeric_factorizations"] = static_cast<double>(c.factorizations);
  s["linear_solves"] = static_cast<double>(c.solves);
  s["cg_iterations"] = static_cast<double>(c.cg_iterations);
  s["newton_iterations"] = static_cast<double>(newton_iterations_);
  s["newton_not_converged"] = static_cast<double>(newton_not_converged_);
  s["assembly_seconds"] = assembly_seconds_;
  s["factorization_seconds"] = factorization_seconds_;
  s["solve_seconds"] = solve_seconds_;
  if (use_multigrid_) s["multigrid_levels"] = static_cast<double>(multigrid_.levels());
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
  // [size of the warm start dv (0 if none), dv..., (with contact pairs of bodies: -(1 + their
  // number of values), the pairs...), the contact set]
  const Impl& m = *impl_;
  std::vector<Real> out;
  out.push_back(m.have_dv_ ? static_cast<Real>(m.dv_.size()) : 0.0);
  if (m.have_dv_) out.insert(out.end(), m.dv_.data(), m.dv_.data() + m.dv_.size());
  if (m.bodies_.saved_size() > 0) {
    out.push_back(-1.0 - static_cast<Real>(m.bodies_.saved_size()));
    m.bodies_.save(out);
  }
  m.contact_.save(out);
  return out;
}

void ImplicitEuler::restore_internal_state(const std::vector<Real>& data) {
  Impl& m = *impl_;
  m.coarse_stale_ = true;  // multigrid: rebuilt from the restored state
  if (data.empty()) {
    m.have_dv_ = false;
    m.contact_.restore(nullptr, 0);
    m.bodies_.restore(nullptr, 0);
    return;
  }
  const Real n = data[0];
  require(n >= 0 && n == std::floor(n) && n + 1 <= static_cast<Real>(data.size()),
          "integrator state (warm start size)", n, "the size of a saved implicit_euler state");
  const size_t size = static_cast<size_t>(n);
  // A warm start of another size (another model) is dropped; prepare() sizes dv_ then.
  const int rows = m.jacobian_ ? m.jacobian_->rows() : m.band_ ? m.band_->rows() : -1;
  m.have_dv_ = size > 0 && (rows < 0 || static_cast<int>(size) == rows);
  if (m.have_dv_) m.dv_ = Eigen::Map<const VecX>(data.data() + 1, static_cast<Eigen::Index>(size));
  size_t at = 1 + size;
  size_t pairs = 0;
  if (at < data.size() && data[at] < 0) {
    const Real count = -1 - data[at];
    require(count >= 0 && count == std::floor(count) &&
                at + 1 + count <= static_cast<Real>(data.size()),
            "integrator state (body contact pairs)", data[at],
            "the size of a saved implicit_euler state");
    pairs = static_cast<size_t>(count);
    ++at;
  }
  m.bodies_.restore(data.data() + at, pairs);
  at += pairs;
  m.contact_.restore(data.data() + at, data.size() - at);
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
      bands != nullptr && bands->dense() && bands->fits(model) && !matrix_free_failed_ &&
      // Contact pairs between bodies and added forces' Jacobians add blocks off the springs'
      // bands: the assembled matrix.
      !(options_.contact == ImplicitContactMode::kImplicit && dynamics.body_contact() != nullptr) &&
      !has_force_jacobians(dynamics);
  const auto size_vectors = [&] {
    for (VecX* w : {&f_, &kw_, &b_, &v1_, &x1_, &g_, &delta_, &rhs_, &z_})
      if (w->size() != n) w->setZero(n);
    if (dv_.size() != n) {  // (a restored warm start of the right size stays)
      dv_.setZero(n);
      have_dv_ = false;
    }
  };
  if (matrix_free) {
    if (!matrix_free_ || !band_ || !band_->built_for(*bands) || band_->rows() != n) {
      const auto start = Clock::now();
      jacobian_.reset();
      solver_.reset();
      a_ = SparseMatrix();
      band_.emplace(*bands, model.num_particles(),
                    options_.cg_tolerance >= kSingleCoefficientsTolerance);
      az_.setZero(n);
      size_vectors();
      matrix_free_ = true;
      use_multigrid_ = false;
      coarse_stale_ = true;
      if (options_.cg_preconditioner == CgPreconditionerKind::kMultigrid)
        use_multigrid_ = multigrid_.build(model, *bands);
      factorization_seconds_ += seconds_since(start);
    }
    if (h != last_h_) coarse_stale_ = true;
    last_h_ = h;
    return StepResult::success();
  }
  if (matrix_free_ || !jacobian_ || jacobian_->rows() != n ||
      jacobian_->num_springs() != model.springs.size()) {
    const auto start = Clock::now();
    matrix_free_ = false;
    use_multigrid_ = false;
    band_.reset();
    extra_blocks_.clear();
    force_blocks_.clear();
    jacobian_.emplace(model);
    a_ = jacobian_->make_matrix();
    CholmodOptions cholmod;
    cholmod.ordering = options_.ordering;
    if (kind == ImplicitLinearSolver::kCholmod) {
      solver_ = std::make_unique<CholmodSolver>(cholmod);
    } else if (kind == ImplicitLinearSolver::kLdlt) {
      solver_ = std::make_unique<LdltSolver>();
    } else {
      CgOptions cg;  // auto's CG is block Jacobi, the fastest measured above its threshold
      cg.preconditioner = !automatic && options_.cg_preconditioner == CgPreconditionerKind::kCholmod
                              ? CgPreconditioner::kLaggedCholesky
                              : CgPreconditioner::kJacobi;
      cg.tolerance = options_.cg_tolerance;
      cg.max_iterations = options_.cg_max_iterations;
      cg.refactor_iterations = options_.refactor_iterations;
      cg.cholmod = cholmod;
      solver_ = std::make_unique<CgSolver>(cg);
    }
    const LinearResult r = solver_->analyze(a_);
    factorization_seconds_ += seconds_since(start);
    if (!r.ok()) return StepResult::failure("implicit_euler: " + r.message);
    size_vectors();
  }
  if (h != last_h_) solver_->invalidate();
  if (h != last_h_) coarse_stale_ = true;
  last_h_ = h;
  return StepResult::success();
}

StepResult ImplicitEuler::Impl::assemble(const Dynamics& dynamics, const VecX& x, const VecX& v,
                                         Real t, Real h) {
  const Model& model = dynamics.model();
  if (matrix_free_ &&
      !band_->assemble(model, x, v, jacobian_options_.definiteness, h, h * h, v, kw_, threads_)) {
    // A collapsed spring (its direction from the rest positions): the assembled matrix.
    matrix_free_failed_ = true;
    if (StepResult r = prepare(dynamics, h); !r.ok) return r;
    solver_->set_threads(threads_);
  }
  if (matrix_free_) {
    ++coarse_age_;
    if (dynamics.anchors() != nullptr) {
      for (const AnchorSpring& anchor : *dynamics.anchors()) {
        band_->add_diagonal(anchor.particle, h * anchor.damping + h * h * anchor.stiffness);
        kw_.segment<3>(3 * anchor.particle) -= anchor.stiffness * v.segment<3>(3 * anchor.particle);
      }
    }
  } else {
    jacobian_->assemble_system(model, x, v, jacobian_options_, h, h * h, a_, v, kw_, threads_);
    if (dynamics.anchors() != nullptr)
      add_anchor_system(*dynamics.anchors(), *jacobian_, h, h * h, a_, v, kw_);
    // The added forces' Jacobians, their symmetric part S = (J + J^T) / 2: a block B at (i, j)
    // puts B / 2 at (i, j) and B^T / 2 at (j, i); A -= h S_D + h^2 S_K, kw += S_K v.
    for (const ForceJacobian::Block& b : force_jacobian_.blocks()) {
      const Mat3 a = -0.5 * (h * b.dfdv + h * h * b.dfdx);
      add_block(a_, b.i, b.j, a);
      add_block(a_, b.j, b.i, a.transpose());
      kw_.segment<3>(3 * b.i) += 0.5 * b.dfdx * v.segment<3>(3 * b.j);
      kw_.segment<3>(3 * b.j) += 0.5 * b.dfdx.transpose() * v.segment<3>(3 * b.i);
    }
  }
  add_external_damping_system(model, t, h);
  return StepResult::success();
}

void ImplicitEuler::Impl::constrain(const VecX& b, bool prescribe, VecX& guess) {
  if (!matrix_free_) {
    contact_.constrain(a_, b, prescribe, rhs_, z_, guess);
    return;
  }
  if (contact_.constrain_rhs(b, prescribe, nullptr, rhs_, z_, guess)) {
    band_->multiply(z_, az_, threads_);
  } else {
    az_.setZero();
  }
  contact_.constrain_rhs(b, prescribe, &az_, rhs_, z_, guess);
}

bool ImplicitEuler::Impl::update_contacts(const Terrains& terrains, const VecX& b, bool commit,
                                          bool screening) {
  if (!matrix_free_) return contact_.update(terrains, b, dv_, commit, a_);
  // The contacts' impulses need A dv at their particles only (a pin's impulse is not used).
  contact_rows_.clear();
  for (const auto& c : contact_.contacts())
    if (!c.pinned) contact_rows_.push_back(c.particle);
  band_->multiply_rows(dv_, contact_rows_, az_, threads_);
  return contact_.update_from_product(terrains, b, dv_, commit, az_, screening);
}

StepResult ImplicitEuler::Impl::solve_matrix_free(const Model& model, const VecX& b, VecX& y,
                                                  bool constrained, Real t, Real tolerance,
                                                  bool resume) {
  auto start = Clock::now();
  // Block Jacobi: the inverses of the (filtered) diagonal blocks (kept when resuming); with
  // multigrid they are its finest smoother's, and its coarse operators are rebuilt when
  // kMultigridMaxAge says so or when the contacts' set is not theirs.
  LinearResult r;
  const ProductFilter filter = constrained ? contact_.product_filter() : ProductFilter{};
  if (!resume) {
    const auto diagonal = [&](int i, Real d[9]) {
      band_->diagonal_block(i, d);
      if (constrained) contact_.filter_diagonal_block(i, d);
    };
    if (use_multigrid_) {
      r = multigrid_.set_diagonal_blocks(model.num_particles(), diagonal, filter, threads_);
      contacts_now_.clear();
      if (constrained)
        for (const ImplicitContact::Contact& c : contact_.contacts())
          contacts_now_.emplace_back(c.particle, c.pinned ? 2 : static_cast<int>(c.mode));
      if (r.ok() &&
          (coarse_stale_ || coarse_age_ >= kMultigridMaxAge || contacts_now_ != coarse_contacts_)) {
        multigrid_.set_operator(*band_, filter, threads_);
        coarse_contacts_ = contacts_now_;
        coarse_stale_ = false;
        coarse_age_ = 0;
        coarse_iterations_ = -1;
      }
    } else {
      r = band_cg_.set_diagonal_blocks(model.num_particles(), diagonal, threads_);
    }
  }
  factorization_seconds_ += seconds_since(start);
  if (r.ok()) {
    start = Clock::now();
    const auto apply = [&](const VecX& in, VecX& out) {
      band_->multiply(in, out, threads_, filter);
    };
    // Resuming: from the iterate as CG left it (before finish_solve's correction), with the
    // iterations the loose solve left, so that it is one solve in every respect.
    if (resume) y = cg_x_;
    const int done = resume ? loose_iterations_ : 0;
    const int limit = options_.cg_max_iterations - done;
    if (use_multigrid_) {
      const auto precondition = [&](const VecX& in, VecX& out) {
        multigrid_.apply(apply, in, out, threads_);
      };
      r = band_cg_.solve(apply, precondition, b, y, tolerance, limit, threads_, resume);
    } else {
      r = band_cg_.solve(apply, b, y, tolerance, limit, threads_, resume);
    }
    r.iterations += done;
    if (use_multigrid_ && tolerance <= options_.cg_tolerance) {
      // Coarse operators that need twice the iterations they needed when built: rebuilt.
      if (coarse_iterations_ < 0) {
        coarse_iterations_ = r.iterations;
      } else if (r.iterations > 2 * coarse_iterations_ + 2) {
        coarse_stale_ = true;
      }
    }
    if (!resume && tolerance > options_.cg_tolerance) {  // a loose solve: kept for resuming
      cg_x_ = y;
      loose_iterations_ = r.iterations;
    }
    solve_seconds_ += seconds_since(start);
  }
  return finish_solve(model, r, b, y, constrained, t);
}

StepResult ImplicitEuler::Impl::ensure_pattern(const Model& model) {
  const std::vector<ImplicitBodyContact::Pair>& pairs = bodies_.pairs();
  const bool complete = std::all_of(pairs.begin(), pairs.end(),
                                    [&](const auto& p) { return has_block(a_, p.i, p.j); });
  if (complete) return StepResult::success();
  const auto start = Clock::now();
  // The union of the candidates so far, unless it grew much larger than the current ones.
  if (extra_blocks_.size() > 4 * pairs.size() + 1024) extra_blocks_.clear();
  for (const auto& p : pairs) extra_blocks_.emplace_back(p.i, p.j);
  std::sort(extra_blocks_.begin(), extra_blocks_.end());
  extra_blocks_.erase(std::unique(extra_blocks_.begin(), extra_blocks_.end()), extra_blocks_.end());
  const StepResult r = rebuild_pattern(model);
  factorization_seconds_ += seconds_since(start);
  return r;
}

StepResult ImplicitEuler::Impl::rebuild_pattern(const Model& model) {
  std::vector<std::pair<int, int>> blocks = extra_blocks_;
  blocks.insert(blocks.end(), force_blocks_.begin(), force_blocks_.end());
  jacobian_.emplace(model, blocks);
  a_ = jacobian_->make_matrix();
  base_saved_ = false;
  const LinearResult r = solver_->analyze(a_);
  if (!r.ok()) return StepResult::failure("implicit_euler: " + r.message);
  return StepResult::success();
}

StepResult ImplicitEuler::Impl::collect_force_jacobians(const Dynamics& dynamics, const VecX& x,
                                                        const VecX& v, Real t) {
  force_jacobian_.clear();
  if (matrix_free_ || !has_force_jacobians(dynamics)) return StepResult::success();
  const Model& model = dynamics.model();
  for (const std::shared_ptr<Force>& force : *dynamics.added_forces()) {
    if (!force->has_jacobian()) continue;
    const std::size_t before = force_jacobian_.blocks().size();
    force->add_jacobian(t, x, v, force_jacobian_);
    for (std::size_t k = before; k < force_jacobian_.blocks().size(); ++k) {
      const ForceJacobian::Block& b = force_jacobian_.blocks()[k];
      const int n = model.num_particles();
      if (b.i < 0 || b.i >= n || b.j < 0 || b.j >= n || !b.dfdx.allFinite() ||
          !b.dfdv.allFinite()) {
        force_jacobian_.validate(n, force->name());  // throws, naming the block
      }
    }
  }
  bool complete = true;
  for (const ForceJacobian::Block& b : force_jacobian_.blocks())
    if (b.i != b.j && !has_block(a_, b.i, b.j)) {
      complete = false;
      force_blocks_.emplace_back(std::min(b.i, b.j), std::max(b.i, b.j));
    }
  if (complete) return StepResult::success();
  const auto start = Clock::now();
  std::sort(force_blocks_.begin(), force_blocks_.end());
  force_blocks_.erase(std::unique(force_blocks_.begin(), force_blocks_.end()), force_blocks_.end());
  const StepResult r = rebuild_pattern(model);
  factorization_seconds_ += seconds_since(start);
  return r;
}

void ImplicitEuler::Impl::refresh_pair_terms() {
  Real* values = a_.valuePtr();
  const size_t nnz = static_cast<size_t>(a_.nonZeros());
  if (!base_saved_) {
    base_values_.assign(values, values + nnz);
    b_base_ = b_;
    base_saved_ = true;
  } else {
    std::copy(base_values_.begin(), base_values_.end(), values);
    b_ = b_base_;
  }
  bodies_.add_terms(a_, &b_);
}

StepResult ImplicitEuler::Impl::factorize_and_solve(const Model& model, const VecX& b, VecX& y,
                                                    bool constrained, Real t, Real cg_tolerance,
                                                    bool resume) {
  if (matrix_free_) {
    return solve_matrix_free(model, b, y, constrained, t,
                             cg_tolerance > 0 ? cg_tolerance : options_.cg_tolerance, resume);
  }
  auto start = Clock::now();
  LinearResult r = solver_->factorize(a_);
  factorization_seconds_ += seconds_since(start);
  if (r.ok()) {
    start = Clock::now();
    r = solver_->solve(b, y);
    solve_seconds_ += seconds_since(start);
  }
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
  base_saved_ = false;
  if (bodies_active_) {
    if (StepResult r = ensure_pattern(model); !r.ok) return r;
  }
  if (StepResult r = collect_force_jacobians(dynamics, s.x, s.v, s.t + h); !r.ok) return r;
  if (StepResult r = assemble(dynamics, s.x, s.v, s.t + h, h); !r.ok) return r;
  anchored_ = dynamics.anchors() != nullptr || !force_jacobian_.empty() || damped_;
  b_.resize(f_.size());
  for_each_entry(threads_, b_.size(), [&](long k) { b_[k] = h * (f_[k] + h * kw_[k]); });
  if (bodies_active_ && bodies_.any_active()) refresh_pair_terms();
  assembly_seconds_ += seconds_since(start);
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
    if (constrained && !resume) constrain(b_, true, dv_);
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
    const bool screening = matrix_free_ && contact_active_ && !bodies_active_ &&
                           screen > options_.cg_tolerance && round < options_.contact_iterations;
    if (StepResult r = solve(screening ? screen : 0, false); !r.ok) return r;
    ++newton_iterations_;
    if (!contact_active_ && !bodies_active_) break;
    const bool last = round >= options_.contact_iterations;
    bool terrain_changed = contact_active_ && update_contacts(*terrains, b_, !last, screening);
    if (screening && !terrain_changed) {
      // The set held on the loose solve: finish the solve at the full tolerance and check again.
      if (StepResult r = solve(0, true); !r.ok) return r;
      terrain_changed = update_contacts(*terrains, b_, !last);
    }
    const bool pairs_changed = bodies_active_ && bodies_.update(dv_, !last);
    if (last || (!terrain_changed && !pairs_changed)) break;
    if (pairs_changed) {
      // The terrains' filter is undone (update() did it if their set changed) before the
      // pairs' terms change.
      if (constrained && !terrain_changed) contact_.unconstrain(a_);
      refresh_pair_terms();
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
    if (StepResult r = collect_force_jacobians(dynamics, x1_, v1_, s.t + h); !r.ok) return r;
    if (StepResult r = assemble(dynamics, x1_, v1_, s.t + h, h); !r.ok) return r;
    if (bodies_active_) bodies_.add_terms(a_, nullptr);
    assembly_seconds_ += seconds_since(start);
    if (constrained) constrain(g_, false, delta_);
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
  if (solver_) solver_->set_threads(threads_);
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
  return StepResult::success();
}

}  // namespace jelly
