#include <jelly/solvers/arkode/detail/arkode_schur.hpp>

#include <algorithm>

#include <arkode/arkode_arkstep.h>

namespace jelly::arkode {

namespace {
// Small systems (the 4x4x4 test cubes) factorize fastest with AMD (and simplicial, the wrapper's
// choice below supernodal_min_rows); larger ones with the wrapper's default (METIS).
CholmodOptions cholmod_options(const Model& model) {
  CholmodOptions options;
  if (model.num_dofs() < SchurSystem::kSupernodalFromDofs) {
    options.ordering = CholmodOrdering::kAmd;
    options.supernodal_min_rows = std::max(options.supernodal_min_rows, model.num_dofs() + 1);
  }
  return options;
}
}  // namespace

SchurSystem::SchurSystem(const Model& model)
    : jacobian_(model),
      k_(jacobian_.make_matrix()),
      d_(jacobian_.make_matrix()),
      s_(jacobian_.make_matrix()),
      cholmod_(cholmod_options(model)) {
  diagonal_.resize(static_cast<size_t>(s_.cols()));
  for (int j = 0; j < s_.cols(); ++j) {
    const int* begin = s_.innerIndexPtr() + s_.outerIndexPtr()[j];
    const int* end = s_.innerIndexPtr() + s_.outerIndexPtr()[j + 1];
    diagonal_[j] = static_cast<int>(std::lower_bound(begin, end, j) - s_.innerIndexPtr());
  }
}

SchurSystem::~SchurSystem() = default;

void SchurSystem::assemble(const Model& model, const VecX& x, const VecX& v,
                           const AnchorSprings* anchors) {
  jacobian_.assemble(model, x, v, JacobianOptions{}, k_, d_);
  if (anchors) add_anchor_jacobians(*anchors, jacobian_, k_, d_);
}

LinearResult SchurSystem::factorize(const Model& model, Real gamma) {
  const Real* kv = k_.valuePtr();
  const Real* dv = d_.valuePtr();
  Real* sv = s_.valuePtr();
  // S = M - gamma D - gamma^2 K on the shared pattern.
  for (Eigen::Index p = 0; p < s_.nonZeros(); ++p) sv[p] = -gamma * dv[p] - gamma * gamma * kv[p];
  for (int j = 0; j < static_cast<int>(diagonal_.size()); ++j)
    sv[diagonal_[j]] += model.mass[j / 3];
  if (!analysed_) {
    const LinearResult r = cholmod_.analyze(s_);
    if (!r.ok()) return r;
    analysed_ = true;
  }
  return cholmod_.factorize(s_);
}

bool SchurSystem::solve(const VecX& r, VecX& out, std::string* why) {
  ensure_size(out, r.size());
  const LinearResult result = cholmod_.solve(r, out);
  if (!result.ok()) *why = result.message;
  return result.ok();
}

namespace {

constexpr int kMaxRefinements = 10;
constexpr Real kRefinementTolerance = 1e-10;

struct SchurContent {
  void* arkode_memory = nullptr;
  const RhsData* data = nullptr;
  std::unique_ptr<SchurSystem> system;
  Real gamma = 0;  // of the last factorization
  VecX x, v, r, dv, residual, correction;
  SchurStatistics statistics;
  std::string error;  // the reason of the last failure
  long last_flag = 0;
};

SchurContent& content(SUNLinearSolver s) { return *static_cast<SchurContent*>(s->content); }

// ARKODE 6.4 never calls setup() of a SUNLINEARSOLVER_MATRIX_EMBEDDED solver, so this one
// presents itself as a matrix-free ("iterative") solver that converges in one iteration: ARKODE
// then calls setup() by its usual heuristics (gamma changed by 20%, every 20 steps, after a
// convergence failure) as long as a preconditioner setup is set (attach_schur_solver).
SUNLinearSolver_Type get_type(SUNLinearSolver) { return SUNLINEARSOLVER_ITERATIVE; }
SUNLinearSolver_ID get_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return SUNLS_SUCCESS; }
// Accept and ignore ARKODE's matrix-vector product and preconditioner: the Schur solve is direct.
int set_atimes(SUNLinearSolver, void*, SUNATimesFn) { return SUNLS_SUCCESS; }
int set_preconditioner(SUNLinearSolver, void*, SUNPSetupFn, SUNPSolveFn) { return SUNLS_SUCCESS; }
int num_iterations(SUNLinearSolver) { return 1; }
realtype residual_norm(SUNLinearSolver) { return 0; }
sunindextype last_flag(SUNLinearSolver s) { return content(s).last_flag; }

// Assembles K, D at ARKODE's current Newton iterate and factorizes S for its current gamma.
int setup(SUNLinearSolver s, SUNMatrix /*unused: the matrix is embedded*/) {
  SchurContent& c = content(s);
  try {
    const Model& model = c.data->dynamics->model();
    const Eigen::Index n = model.num_dofs();
    if (!c.system || c.system->size() != n) c.system = std::make_unique<SchurSystem>(model);
    N_Vector y = nullptr;
    Real gamma = 0;
    if (ARKStepGetCurrentState(c.arkode_memory, &y) != ARK_SUCCESS ||
        ARKStepGetCurrentGamma(c.arkode_memory, &gamma) != ARK_SUCCESS) {
      c.last_flag = SUNLS_MEM_NULL;
      return SUNLS_MEM_NULL;
    }
    const Eigen::Map<const VecX> yy(N_VGetArrayPointer(y), 2 * n);
    c.x = yy.head(n);
    c.v = yy.tail(n);
    c.system->assemble(model, c.x, c.v, c.data->dynamics->anchors());
    ++c.statistics.factorizations;
    const LinearResult r = c.system->factorize(model, gamma);
    if (!r.ok()) {
      c.error = std::string(linear_status_name(r.status)) + ": " + r.message;
      // Not positive definite is recoverable: ARKODE retries with a smaller h (smaller gamma),
      // and M - gamma D - gamma^2 K tends to M.
      const bool recoverable = r.status == LinearStatus::kNotPositiveDefinite;
      if (recoverable) ++c.statistics.not_positive_definite;
      c.last_flag = recoverable ? SUNLS_PACKAGE_FAIL_REC : SUNLS_PACKAGE_FAIL_UNREC;
      return static_cast<int>(c.last_flag);
    }
    c.gamma = gamma;
    c.last_flag = SUNLS_SUCCESS;
    return SUNLS_SUCCESS;
  } catch (const std::bad_alloc&) {
    c.last_flag = SUNLS_MEM_FAIL;
    return SUNLS_MEM_FAIL;
  } catch (const std::exception&) {
    c.last_flag = SUNLS_PACKAGE_FAIL_UNREC;
    return SUNLS_PACKAGE_FAIL_UNREC;
  }
}

// out = (I - g0 J0)^-1 in for the factorized g0 = c.gamma and J0, by the Schur reduction:
// S dv = M in_v + g0 K in_x, out_x = in_x + g0 dv, out_v = dv.
bool schur_solve(SchurContent& c, const Model& model, const Eigen::Ref<const VecX>& in,
                 Eigen::Ref<VecX> out) {
  const Eigen::Index n = c.system->size();
  const Real g = c.gamma;
  c.r.noalias() = g * (c.system->k() * in.head(n));
  for (int i = 0; i < model.num_particles(); ++i)
    c.r.segment<3>(3 * i) += model.mass[i] * in.segment<3>(n + 3 * i);
  if (!c.system->solve(c.r, c.dv, &c.error)) return false;
  out.head(n) = in.head(n) + g * c.dv;
  out.tail(n) = c.dv;
  return true;
}

// x = (I - gamma J0)^-1 b for ARKODE's current gamma. Between two setups gamma changes (up to
// ARKODE's dgmax, 20%) while the factorization keeps g0: iterative refinement with the
// factorized matrix, r = b - (I - gamma J0) x, x += (I - g0 J0)^-1 r, contracts by about
// |gamma - g0| / g0 per iteration and costs a solve and two sparse products, against a
// refactorization that costs tens of solves on the seed cube (docs/arkode.md).
int solve(SUNLinearSolver s, SUNMatrix /*unused*/, N_Vector x, N_Vector b, realtype /*tol*/) {
  SchurContent& c = content(s);
  if (!c.system) return SUNLS_MEM_NULL;
  const Model& model = c.data->dynamics->model();
  const Eigen::Index n = c.system->size();
  const Eigen::Map<const VecX> bb(N_VGetArrayPointer(b), 2 * n);
  Eigen::Map<VecX> xx(N_VGetArrayPointer(x), 2 * n);
  ++c.statistics.solves;
  if (!schur_solve(c, model, bb, xx)) {
    c.last_flag = SUNLS_PACKAGE_FAIL_UNREC;
    return SUNLS_PACKAGE_FAIL_UNREC;
  }
  Real gamma = c.gamma;
  if (ARKStepGetCurrentGamma(c.arkode_memory, &gamma) != ARK_SUCCESS || gamma == c.gamma) {
    c.last_flag = SUNLS_SUCCESS;
    return SUNLS_SUCCESS;
  }
  ensure_size(c.residual, 2 * n);
  ensure_size(c.correction, 2 * n);
  const Real b_norm = bb.norm();
  for (int it = 0; it < kMaxRefinements; ++it) {
    // residual = b - (I - gamma J0) x, J0 x = [x_v; M^-1 (K x_x + D x_v)].
    c.residual.head(n) = bb.head(n) - xx.head(n) + gamma * xx.tail(n);
    c.r.noalias() = c.system->k() * xx.head(n);
    c.r.noalias() += c.system->d() * xx.tail(n);
    for (int i = 0; i < model.num_particles(); ++i)
      c.residual.segment<3>(n + 3 * i) = bb.segment<3>(n + 3 * i) - xx.segment<3>(n + 3 * i) +
                                         (gamma / model.mass[i]) * c.r.segment<3>(3 * i);
    if (c.residual.norm() <= kRefinementTolerance * b_norm) break;
    ++c.statistics.refinements;
    if (!schur_solve(c, model, c.residual, c.correction)) {
      c.last_flag = SUNLS_PACKAGE_FAIL_UNREC;
      return SUNLS_PACKAGE_FAIL_UNREC;
    }
    xx += c.correction;
  }
  c.last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

int free_solver(SUNLinearSolver s) {
  if (s == nullptr) return SUNLS_SUCCESS;
  delete static_cast<SchurContent*>(s->content);
  s->content = nullptr;
  SUNLinSolFreeEmpty(s);
  return SUNLS_SUCCESS;
}

}  // namespace

LinearSolverPtr make_schur_solver(SUNContext context, void* arkode_memory, const RhsData* data) {
  auto c = std::make_unique<SchurContent>();
  c->arkode_memory = arkode_memory;
  c->data = data;
  SUNLinearSolver s = SUNLinSolNewEmpty(context);
  if (s == nullptr) return nullptr;
  s->content = c.release();
  s->ops->gettype = get_type;
  s->ops->getid = get_id;
  s->ops->initialize = initialize;
  s->ops->setatimes = set_atimes;
  s->ops->setpreconditioner = set_preconditioner;
  s->ops->numiters = num_iterations;
  s->ops->resnorm = residual_norm;
  s->ops->setup = setup;
  s->ops->solve = solve;
  s->ops->lastflag = last_flag;
  s->ops->free = free_solver;
  return LinearSolverPtr(s);
}

namespace {
int no_preconditioner_setup(realtype, N_Vector, N_Vector, booleantype, booleantype* jcur, realtype,
                            void*) {
  *jcur = SUNTRUE;
  return 0;
}
int no_preconditioner_solve(realtype, N_Vector, N_Vector, N_Vector r, N_Vector z, realtype,
                            realtype, int, void*) {
  N_VScale(1.0, r, z);
  return 0;
}
}  // namespace

int attach_schur_solver(void* arkode_memory, SUNLinearSolver solver) {
  int flag = ARKStepSetLinearSolver(arkode_memory, solver, nullptr);
  // ARKODE 6.4 disables the linear solver setup when there is neither a matrix nor a
  // preconditioner setup; a no-op preconditioner keeps it, so that setup() factorizes.
  if (flag >= 0)
    flag =
        ARKStepSetPreconditioner(arkode_memory, no_preconditioner_setup, no_preconditioner_solve);
  return flag;
}

const std::string& schur_error(SUNLinearSolver solver) { return content(solver).error; }

const SchurStatistics& schur_statistics(SUNLinearSolver solver) {
  return content(solver).statistics;
}

}  // namespace jelly::arkode
