#include <jelly/solvers/linear/detail/cholmod_solver.hpp>

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

const std::vector<EnumName<CholmodOrdering>>& cholmod_orderings() {
  static const std::vector<EnumName<CholmodOrdering>> table{
      {CholmodOrdering::kAmd, "amd", "approximate minimum degree"},
      {CholmodOrdering::kMetis, "metis", "METIS nested dissection (least fill on the seed cube)"},
      {CholmodOrdering::kNesdis, "nesdis", "CHOLMOD's nested dissection"},
      {CholmodOrdering::kBest, "best", "CHOLMOD's default: AMD, METIS when AMD fills much"},
  };
  return table;
}

std::string_view cholmod_ordering_name(CholmodOrdering ordering) {
  return name_of(cholmod_orderings(), ordering);
}

namespace {

void silent_error_handler(int /*status*/, const char* /*file*/, int /*line*/,
                          const char* /*message*/) {}

// CHOLMOD's status codes (cholmod_core.h) as a result with a reason.
LinearResult from_status(int status, const std::string& what) {
  switch (status) {
    case CHOLMOD_OK:
      return {};
    case CHOLMOD_NOT_POSDEF:
      return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                   "CHOLMOD: " + what + ": matrix not positive definite");
    case CHOLMOD_DSMALL:
      // A warning: the factorization succeeded but a diagonal entry of L is tiny.
      return {};
    case CHOLMOD_OUT_OF_MEMORY:
      return LinearResult::failure(LinearStatus::kOutOfMemory,
                                   "CHOLMOD: " + what + ": out of memory");
    case CHOLMOD_TOO_LARGE:
      return LinearResult::failure(LinearStatus::kOutOfMemory,
                                   "CHOLMOD: " + what + ": problem too large (integer overflow)");
    case CHOLMOD_INVALID:
      return LinearResult::failure(LinearStatus::kInvalidInput,
                                   "CHOLMOD: " + what + ": invalid input");
    case CHOLMOD_NOT_INSTALLED:
      return LinearResult::failure(LinearStatus::kFailure,
                                   "CHOLMOD: " + what + ": method not installed");
    case CHOLMOD_GPU_PROBLEM:
      return LinearResult::failure(LinearStatus::kFailure, "CHOLMOD: " + what + ": GPU problem");
    default:
      return LinearResult::failure(
          LinearStatus::kFailure,
          "CHOLMOD: " + what + ": unknown status " + std::to_string(status));
  }
}

}  // namespace

struct CholmodSolver::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  cholmod_dense* x = nullptr;  // solve2 workspaces, reused
  cholmod_dense* y = nullptr;
  cholmod_dense* e = nullptr;
  cholmod_sparse view{};             // the caller's matrix, not owned
  cholmod_sparse* update = nullptr;  // columns of a diagonal update, capacity rows
  std::vector<int> inverse_perm;     // row i of A is row inverse_perm[i] of the factor
  long rank_updates = 0;
  bool factorized = false;
  int rows = 0;
  long nnz = 0;

  CholmodOptions options;

  explicit Impl(const CholmodOptions& o) : options(o) {
    cholmod_start(&common);
    common.print = 0;
    common.error_handler = &silent_error_handler;
    common.final_ll = 1;
    switch (options.ordering) {
      case CholmodOrdering::kAmd:
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_AMD;
        break;
      case CholmodOrdering::kMetis:
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_METIS;
        break;
      case CholmodOrdering::kNesdis:
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_NESDIS;
        break;
      case CholmodOrdering::kBest:
        break;
    }
    common.postorder = 1;
  }
  ~Impl() {
    free_all();
    cholmod_finish(&common);
  }
  void free_all() {
    if (factor) cholmod_free_factor(&factor, &common);
    if (x) cholmod_free_dense(&x, &common);
    if (y) cholmod_free_dense(&y, &common);
    if (e) cholmod_free_dense(&e, &common);
    if (update) cholmod_free_sparse(&update, &common);
    inverse_perm.clear();
    factorized = false;
  }
  // A view of the lower triangle of `a` (stype -1: CHOLMOD ignores the upper triangle).
  void wrap(const SparseMatrix& a) {
    view.nrow = static_cast<size_t>(a.rows());
    view.ncol = static_cast<size_t>(a.cols());
    view.nzmax = static_cast<size_t>(a.nonZeros());
    view.p = const_cast<int*>(a.outerIndexPtr());
    view.i = const_cast<int*>(a.innerIndexPtr());
    view.nz = nullptr;
    view.x = const_cast<Real*>(a.valuePtr());
    view.z = nullptr;
    view.stype = -1;
    view.itype = CHOLMOD_INT;
    view.xtype = CHOLMOD_REAL;
    view.dtype = CHOLMOD_DOUBLE;
    view.sorted = 1;
    view.packed = 1;
  }
};

CholmodSolver::CholmodSolver(CholmodOptions options) : impl_(std::make_unique<Impl>(options)) {}
CholmodSolver::~CholmodSolver() = default;

bool CholmodSolver::factorized() const { return impl_->factorized; }
long CholmodSolver::rank_updates() const { return impl_->rank_updates; }

LinearResult CholmodSolver::update_diagonal(const std::vector<int>& rows,
                                            const std::vector<Real>& d, bool add) {
  Impl& m = *impl_;
  if (!m.factorized)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CHOLMOD: update without a successful factorization");
  if (rows.size() != d.size())
    return LinearResult::failure(LinearStatus::kInvalidInput, "CHOLMOD: update: size mismatch");
  if (rows.empty()) return {};
  const int n = m.rows;
  if (m.update == nullptr) {
    m.update = cholmod_allocate_sparse(n, n, n, 1, 1, 0, CHOLMOD_REAL, &m.common);
    if (m.update == nullptr)
      return LinearResult::failure(LinearStatus::kOutOfMemory, "CHOLMOD: update: out of memory");
    const int* perm = static_cast<const int*>(m.factor->Perm);
    m.inverse_perm.assign(n, 0);
    for (int k = 0; k < n; ++k) m.inverse_perm[perm ? perm[k] : k] = k;
  }
  // Columns sqrt(d_k) e_(p(row_k)), in the factor's permuted order; CHOLMOD updates up to eight
  // at a time, so they are passed in one call.
  int* p = static_cast<int*>(m.update->p);
  int* i = static_cast<int*>(m.update->i);
  Real* x = static_cast<Real*>(m.update->x);
  size_t done = 0;
  while (done < rows.size()) {
    const size_t count = std::min(rows.size() - done, static_cast<size_t>(n));
    p[0] = 0;
    for (size_t k = 0; k < count; ++k) {
      const int row = rows[done + k];
      if (row < 0 || row >= n || !(d[done + k] >= 0))
        return LinearResult::failure(LinearStatus::kInvalidInput,
                                     "CHOLMOD: update: bad row or negative value");
      i[k] = m.inverse_perm[row];
      x[k] = std::sqrt(d[done + k]);
      p[k + 1] = static_cast<int>(k + 1);
    }
    m.update->ncol = count;
    m.common.status = CHOLMOD_OK;
    const int ok = cholmod_updown(add ? 1 : 0, m.update, m.factor, &m.common);
    m.rank_updates += static_cast<long>(count);
    LinearResult r = from_status(m.common.status, add ? "update" : "downdate");
    if (r.ok() && !ok) r = LinearResult::failure(LinearStatus::kFailure, "CHOLMOD: update failed");
    if (!r.ok()) {
      m.factorized = false;
      return r;
    }
    done += count;
  }
  m.update->ncol = static_cast<size_t>(n);
  return {};
}
double CholmodSolver::factor_non_zeros() const { return impl_->common.lnz; }
double CholmodSolver::factor_flops() const { return impl_->common.fl; }

LinearResult CholmodSolver::analyze(const SparseMatrix& a) {
  if (a.rows() != a.cols() || !a.isCompressed())
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CHOLMOD: analyze: the matrix must be square and compressed");
  impl_->free_all();
  impl_->wrap(a);
  impl_->common.status = CHOLMOD_OK;
  impl_->common.supernodal =
      a.rows() >= impl_->options.supernodal_min_rows ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
  {
    // One analysis at a time in the process: METIS keeps its random generator's state in
    // globals, so two orderings computed at once (fit windows or Ceres residual blocks on
    // several threads) interleave it and come out as the timing makes them.
    static std::mutex analysis;
    const std::lock_guard<std::mutex> one_at_a_time(analysis);
    const parallel::SerialLibraries serial;
    impl_->factor = cholmod_analyze(&impl_->view, &impl_->common);
  }
  ++counters_.analyses;
  if (impl_->factor == nullptr) {
    LinearResult r = from_status(impl_->common.status, "analyze");
    if (r.ok()) r = LinearResult::failure(LinearStatus::kFailure, "CHOLMOD: analyze failed");
    return r;
  }
  impl_->rows = static_cast<int>(a.rows());
  impl_->nnz = static_cast<long>(a.nonZeros());
  return {};
}

LinearResult CholmodSolver::factorize(const SparseMatrix& a) {
  Impl& m = *impl_;
  if (m.factor == nullptr)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CHOLMOD: factorize called before analyze");
  if (a.rows() != m.rows || a.nonZeros() != m.nnz || !a.isCompressed())
    return LinearResult::failure(
        LinearStatus::kInvalidInput,
        "CHOLMOD: factorize: the matrix does not have the analysed pattern");
  m.wrap(a);
  m.factorized = false;
  m.common.status = CHOLMOD_OK;
  int ok = 0;
  {
    const parallel::SerialLibraries serial;
    ok = cholmod_factorize(&m.view, m.factor, &m.common);
  }
  ++counters_.factorizations;
  const int status = m.common.status;
  if (status == CHOLMOD_NOT_POSDEF || m.factor->minor < m.factor->n) {
    return LinearResult::failure(LinearStatus::kNotPositiveDefinite,
                                 "CHOLMOD: matrix not positive definite (leading minor of order " +
                                     std::to_string(m.factor->minor + 1) + " of " +
                                     std::to_string(m.factor->n) + " is not positive)");
  }
  LinearResult r = from_status(status, "factorize");
  if (r.ok() && !ok) r = LinearResult::failure(LinearStatus::kFailure, "CHOLMOD: factorize failed");
  m.factorized = r.ok();
  return r;
}

LinearResult CholmodSolver::solve(const VecX& b, VecX& x) {
  if (b.size() != impl_->rows || x.size() != impl_->rows)
    return LinearResult::failure(LinearStatus::kInvalidInput, "CHOLMOD: solve: wrong vector size");
  return solve_raw(b.data(), x.data(), 1);
}

LinearResult CholmodSolver::solve_columns(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) {
  if (b.rows() != impl_->rows || x.rows() != b.rows() || x.cols() != b.cols() || b.cols() < 1)
    return LinearResult::failure(LinearStatus::kInvalidInput, "CHOLMOD: solve: wrong matrix size");
  return solve_raw(b.data(), x.data(), static_cast<int>(b.cols()));
}

LinearResult CholmodSolver::solve_raw(const Real* b, Real* x, int columns) {
  Impl& m = *impl_;
  if (!m.factorized)
    return LinearResult::failure(LinearStatus::kInvalidInput,
                                 "CHOLMOD: solve without a successful factorization");
  cholmod_dense rhs{};
  rhs.nrow = static_cast<size_t>(m.rows);
  rhs.ncol = static_cast<size_t>(columns);
  rhs.nzmax = static_cast<size_t>(m.rows) * columns;
  rhs.d = static_cast<size_t>(m.rows);
  rhs.x = const_cast<Real*>(b);
  rhs.z = nullptr;
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  m.common.status = CHOLMOD_OK;
  int ok = 0;
  {
    const parallel::SerialLibraries serial;
    ok = cholmod_solve2(CHOLMOD_A, m.factor, &rhs, nullptr, &m.x, nullptr, &m.y, &m.e, &m.common);
  }
  ++counters_.solves;
  LinearResult r = from_status(m.common.status, "solve");
  if (r.ok() && !ok) r = LinearResult::failure(LinearStatus::kFailure, "CHOLMOD: solve failed");
  if (!r.ok()) return r;
  const Real* out = static_cast<const Real*>(m.x->x);
  std::copy(out, out + static_cast<size_t>(m.rows) * columns, x);
  return r;
}

}  // namespace jelly
