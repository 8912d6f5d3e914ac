#include <jelly/solvers/arkode/detail/arkode_dirk.hpp>

#include <algorithm>
#include <vector>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_butcher_dirk.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/arkode/detail/arkode_iterative.hpp>
#include <jelly/solvers/arkode/detail/arkode_schur.hpp>
#include <jelly/solvers/arkode/detail/arkode_support.hpp>

namespace jelly {

namespace {

constexpr Real kDeltaGammaMax = 1e-2;
constexpr int kMaximumOrderPredictor = 1;
constexpr int kGmresMaxKrylov = 10;
constexpr int kInterpolantDegree = 3;

// "auto": the matrix-free Schur CG, the fastest in every measurement of docs/arkode.md
// ("Iterative Newton solves").
ArkodeLinearSolver resolve_linear_solver(ArkodeLinearSolver kind) {
  return kind == ArkodeLinearSolver::kAuto ? ArkodeLinearSolver::kCg : kind;
}

class DirkDriver final : public arkode::Driver {
 public:
  DirkDriver(const ArkodeOptions& options, std::string method, ArkodeLinearSolver linear_solver)
      : Driver("arkode_dirk", arkode::kArkStepApi, options),
        method_(std::move(method)),
        linear_solver_kind_(linear_solver) {
    data_.owner = this;
  }
  ArkodeLinearSolver linear_solver_kind() const { return linear_solver_kind_; }
  // ARKODE's memory refers to the linear solver and matrix: free it first.
  ~DirkDriver() override { memory_.reset(); }

 protected:
  int create(realtype t0, N_Vector y0) override {
    memory_.reset();  // before the solvers it uses
    linear_solver_.reset();
    jacobian_.reset();
    memory_.reset(ARKStepCreate(nullptr, arkode::rhs, t0, y0, context_.get()));
    if (!memory_) return ARK_MEM_FAIL;
    void* m = memory_.get();
    int flag = ARKStepSetErrHandlerFn(m, arkode::keep_error, &data_);
    if (flag >= 0) flag = ARKStepSetTableName(m, method_.c_str(), "ARKODE_ERK_NONE");
    if (flag < 0) return flag;
    if (linear_solver_kind_ == ArkodeLinearSolver::kGmres) {
      linear_solver_.reset(SUNLinSol_SPGMR(y0, SUN_PREC_RIGHT, kGmresMaxKrylov, context_.get()));
      if (!linear_solver_) return ARK_MEM_FAIL;
      flag = ARKStepSetLinearSolver(m, linear_solver_.get(), nullptr);
      if (flag >= 0)
        flag = ARKStepSetPreconditioner(m, &DirkDriver::preconditioner_setup,
                                        &DirkDriver::preconditioner_solve);
    } else if (linear_solver_kind_ == ArkodeLinearSolver::kJacobi ||
               linear_solver_kind_ == ArkodeLinearSolver::kCg) {
      linear_solver_ = arkode::make_iterative_solver(context_.get(), m, &data_,
                                                     linear_solver_kind_ == ArkodeLinearSolver::kCg
                                                         ? arkode::IterativeMode::kCg
                                                         : arkode::IterativeMode::kJacobi);
      if (!linear_solver_) return ARK_MEM_FAIL;
      flag = arkode::attach_schur_solver(m, linear_solver_.get());
    } else if (linear_solver_kind_ == ArkodeLinearSolver::kKlu) {
      const sunindextype n = N_VGetLength(y0) / 2;
      const Model& model = data_.dynamics->model();
      schur_ = std::make_unique<arkode::SchurSystem>(model);  // K, D on their fixed pattern
      const auto nnz =
          static_cast<sunindextype>(2 * n + schur_->k().nonZeros() + schur_->d().nonZeros());
      jacobian_.reset(SUNSparseMatrix(2 * n, 2 * n, nnz, CSC_MAT, context_.get()));
      if (!jacobian_) return ARK_MEM_FAIL;
      build_pattern(n);
      linear_solver_.reset(SUNLinSol_KLU(y0, jacobian_.get(), context_.get()));
      if (!linear_solver_) return ARK_MEM_FAIL;
      flag = ARKStepSetLinearSolver(m, linear_solver_.get(), jacobian_.get());
      if (flag >= 0) flag = ARKStepSetJacFn(m, &DirkDriver::jacobian);
    } else {
      linear_solver_ = arkode::make_schur_solver(context_.get(), m, &data_);
      if (!linear_solver_) return ARK_MEM_FAIL;
      flag = arkode::attach_schur_solver(m, linear_solver_.get());
    }
    // ARKODE refactors when gamma = h a_ii changed by more than dgmax (default 20%) since the
    // last setup. Between, the Newton corrections use the old gamma, and its convergence test
    // (del * rate < tolerance, with the rate of an earlier, exact-Jacobian iteration) accepts
    // them after one iteration: on the damped oscillator the global error then stopped
    // following rtol (docs/arkode.md). The Schur solver refines its solution to the current
    // gamma instead; for KLU a tighter bound (kDeltaGammaMax) restores the accuracy.
    if (flag >= 0 && linear_solver_kind_ == ArkodeLinearSolver::kKlu)
      flag = ARKStepSetDeltaGammaMax(m, kDeltaGammaMax);
    // Newton starts from the interpolant of the last step (ARKODE's "maximum order" predictor)
    // rather than from y_n: on a spinning cube of stiff springs the trivial predictor made most
    // steps fail Newton's convergence test and took many times as many steps (docs/arkode.md).
    // After a restart ARKODE falls back to y_n.
    if (flag >= 0) flag = ARKStepSetPredictorMethod(m, kMaximumOrderPredictor);
    // ARKODE's default Hermite interpolant for this order-5 method has degree 5, which costs
    // extra right-hand sides per step and makes every prediction a long linear combination;
    // degree 3 uses only the step's end values (docs/arkode.md has the counts).
    if (flag >= 0) flag = ARKStepSetInterpolantDegree(m, kInterpolantDegree);
    return flag;
  }

  // A DIRK step is expensive: the driver steps past the interval end and interpolates there
  // (docs/arkode.md, "Contact"), so that contact-free intervals cost no step of their own.
  bool interpolates() const override { return true; }

  std::string failure_detail() const override {
    if (linear_solver_kind_ != ArkodeLinearSolver::kSchur || !linear_solver_) return {};
    const std::string& why = arkode::schur_error(linear_solver_.get());
    return why.empty() ? why : "Schur solve: " + why;
  }

  arkode::Counters read_counters() const override {
    arkode::Counters c = Driver::read_counters();
    void* m = memory_.get();
    long fe = 0;
    ARKStepGetNumRhsEvals(m, &fe, &c.rhs_evaluations);
    ARKStepGetNumNonlinSolvIters(m, &c.newton_iterations);
    ARKStepGetNumNonlinSolvConvFails(m, &c.newton_failures);
    ARKStepGetNumLinSolvSetups(m, &c.linear_setups);
    if (linear_solver_kind_ == ArkodeLinearSolver::kKlu)
      ARKStepGetNumJacEvals(m, &c.jacobian_evaluations);
    if (linear_solver_kind_ == ArkodeLinearSolver::kGmres) {
      ARKStepGetNumLinIters(m, &c.linear_iterations);
      ARKStepGetNumLinConvFails(m, &c.linear_failures);
      ARKStepGetNumLinRhsEvals(m, &c.linear_rhs_evaluations);
    }
    return c;
  }

  void add_statistics(Statistics& s) const override {
    s["newton_iterations"] = static_cast<double>(total().newton_iterations);
    s["newton_convergence_failures"] = static_cast<double>(total().newton_failures);
    s["linear_setups"] = static_cast<double>(total().linear_setups);
    if (linear_solver_kind_ == ArkodeLinearSolver::kKlu) {
      s["jacobian_evaluations"] = static_cast<double>(total().jacobian_evaluations);
    } else if (linear_solver_kind_ == ArkodeLinearSolver::kGmres) {
      s["krylov_iterations"] = static_cast<double>(total().linear_iterations);
      s["krylov_failures"] = static_cast<double>(total().linear_failures);
      s["jv_rhs_evaluations"] = static_cast<double>(total().linear_rhs_evaluations);
      s["preconditioner_setups"] = static_cast<double>(preconditioner_.linearizations());
    } else if (linear_solver_kind_ == ArkodeLinearSolver::kJacobi ||
               linear_solver_kind_ == ArkodeLinearSolver::kCg) {
      if (linear_solver_) {
        const arkode::IterativeStatistics& i = arkode::iterative_statistics(linear_solver_.get());
        s["linearizations"] = static_cast<double>(i.setups);
        if (linear_solver_kind_ == ArkodeLinearSolver::kCg) {
          s["cg_iterations"] = static_cast<double>(i.iterations);
          s["cg_failures"] = static_cast<double>(i.failures);
        }
      }
    } else if (linear_solver_) {
      const arkode::SchurStatistics& schur = arkode::schur_statistics(linear_solver_.get());
      s["schur_factorizations"] = static_cast<double>(schur.factorizations);
      s["schur_not_positive_definite"] = static_cast<double>(schur.not_positive_definite);
      s["schur_refinements"] = static_cast<double>(schur.refinements);
    }
  }

 private:
  // The CSC pattern of J = [[0, I], [M^-1 K, M^-1 D]], with the diagonal stored explicitly so
  // that ARKODE's I - gamma J keeps the pattern (no reallocation). Kept here because ARKODE
  // zeroes the matrix, pattern included (SUNMatZero_Sparse), before each Jacobian evaluation.
  void build_pattern(sunindextype n) {
    const SparseMatrix& k = schur_->k();
    const SparseMatrix& d = schur_->d();
    column_start_.assign(static_cast<size_t>(2 * n + 1), 0);
    row_index_.clear();
    row_index_.reserve(static_cast<size_t>(2 * n + k.nonZeros() + d.nonZeros()));
    for (sunindextype j = 0; j < 2 * n; ++j) {
      column_start_[j] = static_cast<sunindextype>(row_index_.size());
      const SparseMatrix& block = j < n ? k : d;
      const sunindextype jj = j < n ? j : j - n;
      row_index_.push_back(jj);  // (j, j) in the top-left zero block, or (j - n, j) in I
      for (SparseMatrix::InnerIterator it(block, jj); it; ++it) row_index_.push_back(n + it.row());
    }
    column_start_[2 * n] = static_cast<sunindextype>(row_index_.size());
  }

  // ARKLsJacFn: refills K, D at y and writes J's values in the fixed pattern.
  static int jacobian(realtype /*t*/, N_Vector y, N_Vector /*fy*/, SUNMatrix jac, void* user_data,
                      N_Vector, N_Vector, N_Vector) {
    auto& data = *static_cast<arkode::RhsData*>(user_data);
    auto& self = *static_cast<DirkDriver*>(data.owner);
    const Model& model = data.dynamics->model();
    const sunindextype n = model.num_dofs();
    const Eigen::Map<const VecX> yy(N_VGetArrayPointer(y), 2 * n);
    data.x = yy.head(n);
    data.v = yy.tail(n);
    self.schur_->assemble(model, data.x, data.v, data.dynamics->anchors());
    std::copy(self.column_start_.begin(), self.column_start_.end(),
              SUNSparseMatrix_IndexPointers(jac));
    std::copy(self.row_index_.begin(), self.row_index_.end(), SUNSparseMatrix_IndexValues(jac));
    Real* value = SUNSparseMatrix_Data(jac);
    const sunindextype* row = self.row_index_.data();
    const SparseMatrix& k = self.schur_->k();
    const SparseMatrix& d = self.schur_->d();
    sunindextype p = 0;
    for (sunindextype j = 0; j < 2 * n; ++j) {
      const SparseMatrix& block = j < n ? k : d;
      value[p++] = j < n ? 0.0 : 1.0;
      const Real* src = block.valuePtr() + block.outerIndexPtr()[j < n ? j : j - n];
      const sunindextype count = self.column_start_[j + 1] - p;
      for (sunindextype q = 0; q < count; ++q, ++p)
        value[p] = src[q] / model.mass[(row[p] - n) / 3];
    }
    return 0;
  }

  // ARKLsPrecSetupFn ("gmres"): the diagonal blocks of K and D at y, unless ARKODE says the
  // last ones will do (jok).
  static int preconditioner_setup(realtype t, N_Vector y, N_Vector /*fy*/, booleantype jok,
                                  booleantype* jcur, realtype /*gamma*/, void* user_data) {
    auto& data = *static_cast<arkode::RhsData*>(user_data);
    auto& self = *static_cast<DirkDriver*>(data.owner);
    if (jok && self.preconditioner_.ready()) {
      *jcur = SUNFALSE;
      return 0;
    }
    const Model& model = data.dynamics->model();
    const sunindextype n = model.num_dofs();
    const Eigen::Map<const VecX> yy(N_VGetArrayPointer(y), 2 * n);
    data.x = yy.head(n);
    data.v = yy.tail(n);
    data.dynamics->added_force_jacobians(t, data.x, data.v, self.forces_);
    self.preconditioner_.linearize(model, data.x, data.v, data.dynamics->anchors(), t,
                                   &self.forces_);
    *jcur = SUNTRUE;
    return 0;
  }

  // ARKLsPrecSolveFn ("gmres"): z = P^-1 r for ARKODE's current gamma.
  static int preconditioner_solve(realtype /*t*/, N_Vector /*y*/, N_Vector /*fy*/, N_Vector r,
                                  N_Vector z, realtype gamma, realtype /*delta*/, int /*lr*/,
                                  void* user_data) {
    auto& data = *static_cast<arkode::RhsData*>(user_data);
    auto& self = *static_cast<DirkDriver*>(data.owner);
    if (!self.preconditioner_.ready()) return -1;
    const Model& model = data.dynamics->model();
    self.preconditioner_.set_gamma(model, gamma);
    self.preconditioner_.block_jacobi(model, N_VGetArrayPointer(r), N_VGetArrayPointer(z));
    return 0;
  }

  std::string method_;
  ArkodeLinearSolver linear_solver_kind_;               // kAuto resolved
  arkode::SpringOperator preconditioner_;               // gmres: the block Jacobi
  ForceJacobian forces_;                                // gmres: the added forces' blocks
  std::unique_ptr<arkode::SchurSystem> schur_;          // klu: the K, D assembly
  std::vector<sunindextype> column_start_, row_index_;  // klu: the pattern of J
  arkode::MatrixPtr jacobian_;
  arkode::LinearSolverPtr linear_solver_;
};

}  // namespace

ArkodeDirk::ArkodeDirk(const ArkodeOptions& options) {
  options.validate("ArkodeOptions.");
  const std::string method = options.method.empty() ? kDefaultMethod : options.method;
  const int id = arkode_method_id(arkode_dirk_methods(), method, kDefaultMethod);
  ARKodeButcherTable table = ARKodeButcherTable_LoadDIRK(static_cast<ARKODE_DIRKTableID>(id));
  const bool embedded = table != nullptr && table->d != nullptr;
  if (table != nullptr) {
    order_ = table->q;
    ARKodeButcherTable_Free(table);
  }
  require(embedded, "integrator.options.method", method,
          "a diagonally implicit table of ARKODE with an embedding");
  const ArkodeLinearSolver kind = resolve_linear_solver(options.linear_solver);
  uses_force_jacobians_ = kind == ArkodeLinearSolver::kCg || kind == ArkodeLinearSolver::kJacobi ||
                          kind == ArkodeLinearSolver::kGmres;
  driver_ = std::make_unique<DirkDriver>(options, method, kind);
}

ArkodeDirk::~ArkodeDirk() = default;

StepResult ArkodeDirk::do_step(const Dynamics& dynamics, State& state, Real h) {
  return driver_->advance(dynamics, state, h);
}

Statistics ArkodeDirk::statistics() const {
  Statistics s = driver_->statistics();
  for (const auto& [key, value] : Integrator::statistics()) s[key] = value;
  return s;
}

}  // namespace jelly
