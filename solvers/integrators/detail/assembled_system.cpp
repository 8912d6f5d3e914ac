#include <jelly/solvers/integrators/detail/assembled_system.hpp>

#include <algorithm>

#include <jelly/core/detail/anchor_jacobian.hpp>
#include <jelly/core/detail/clock.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/implicit_contact.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/solvers/linear/detail/cholmod_solver.hpp>
#include <jelly/solvers/linear/detail/ldlt_solver.hpp>

namespace jelly {

namespace {

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

std::unique_ptr<LinearSolver> make_linear_solver(ImplicitLinearSolver kind, bool automatic,
                                                 const ImplicitEulerOptions& options) {
  CholmodOptions cholmod;
  cholmod.ordering = options.ordering;
  if (kind == ImplicitLinearSolver::kCholmod) return std::make_unique<CholmodSolver>(cholmod);
  if (kind == ImplicitLinearSolver::kLdlt) return std::make_unique<LdltSolver>();
  CgOptions cg;  // auto's CG is block Jacobi (the fastest measured above its threshold) or amg
  cg.preconditioner = CgPreconditioner::kJacobi;
  if (!automatic && options.cg_preconditioner == CgPreconditionerKind::kCholmod)
    cg.preconditioner = CgPreconditioner::kLaggedCholesky;
  if (options.cg_preconditioner == CgPreconditionerKind::kAmg)
    cg.preconditioner = CgPreconditioner::kAmg;
  cg.tolerance = options.cg_tolerance;
  cg.max_iterations = options.cg_max_iterations;
  cg.refactor_iterations = options.refactor_iterations;
  if (options.amg_cycle == AmgCycle::kV) {
    cg.amg_coarse_degree = 2;
    cg.amg_w_cycle = false;
  }
  cg.cholmod = cholmod;
  return std::make_unique<CgSolver>(cg);
}

}  // namespace

AssembledSystem::AssembledSystem(const Model& model, ImplicitLinearSolver solver, bool automatic,
                                 const ImplicitEulerOptions& options, SystemTimes& times)
    : solver_(make_linear_solver(solver, automatic, options)), times_(times) {
  cg_ = dynamic_cast<CgSolver*>(solver_.get());
  jacobian_options_.definiteness = options.definiteness;
  jacobian_.emplace(model);
  a_ = jacobian_->make_matrix();
}

StepResult AssembledSystem::analyze() {
  const LinearResult r = solver_->analyze(a_);
  if (!r.ok()) return StepResult::failure("implicit_euler: " + r.message);
  return StepResult::success();
}

bool AssembledSystem::fits(const Model& model) const {
  return jacobian_->rows() == model.num_dofs() && jacobian_->num_springs() == model.springs.size();
}

void AssembledSystem::set_threads(int threads) {
  threads_ = threads;
  solver_->set_threads(threads);
}

bool AssembledSystem::assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real h,
                               VecX& kw) {
  const Model& model = dynamics.model();
  // Amg: the rigid-body modes of its near-null space at the positions of this step.
  if (cg_ != nullptr && cg_->needs_coordinates()) cg_->set_coordinates(x);
  jacobian_->assemble_system(model, x, v, jacobian_options_, h, h * h, a_, v, kw, threads_);
  if (dynamics.anchors() != nullptr)
    add_anchor_system(*dynamics.anchors(), *jacobian_, h, h * h, a_, v, kw);
  // The added forces' Jacobians, their symmetric part S = (J + J^T) / 2: a block B at (i, j)
  // puts B / 2 at (i, j) and B^T / 2 at (j, i); A -= h S_D + h^2 S_K, kw += S_K v.
  for (const ForceJacobian::Block& b : force_jacobian_.blocks()) {
    const Mat3 a = -0.5 * (h * b.dfdv + h * h * b.dfdx);
    add_block(a_, b.i, b.j, a);
    add_block(a_, b.j, b.i, a.transpose());
    kw.segment<3>(3 * b.i) += 0.5 * b.dfdx * v.segment<3>(3 * b.j);
    kw.segment<3>(3 * b.j) += 0.5 * b.dfdx.transpose() * v.segment<3>(3 * b.i);
  }
  return true;
}

void AssembledSystem::add_diagonal(int particle, Real value) {
  for (int d = 0; d < 3; ++d) jacobian_->add_to_diagonal(a_, 3 * particle + d, value);
}

void AssembledSystem::constrain(ImplicitContact& contacts, const VecX& b, bool prescribe, VecX& rhs,
                                VecX& z, VecX& guess) {
  contacts.constrain(a_, b, prescribe, rhs, z, guess);
}

bool AssembledSystem::update_contacts(ImplicitContact& contacts, const Terrains& terrains,
                                      const VecX& b, const VecX& dv, bool commit,
                                      bool /*screening*/) {
  return contacts.update(terrains, b, dv, commit, a_);
}

LinearResult AssembledSystem::solve(const VecX& b, VecX& y, ImplicitContact* /*constraints*/,
                                    Real /*tolerance*/, bool /*resume*/) {
  // (The contact filter is in a_ already; the iterative solver's tolerance is its own option.)
  auto start = Clock::now();
  LinearResult r = solver_->factorize(a_);
  times_.factorization += seconds_since(start);
  if (r.ok()) {
    start = Clock::now();
    r = solver_->solve(b, y);
    times_.solve += seconds_since(start);
  }
  return r;
}

StepResult AssembledSystem::collect_force_jacobians(const Dynamics& dynamics, const VecX& x,
                                                    const VecX& v, Real t) {
  dynamics.added_force_jacobians(t, x, v, force_jacobian_);
  if (force_jacobian_.empty()) return StepResult::success();
  const Model& model = dynamics.model();
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
  times_.factorization += seconds_since(start);
  return r;
}

StepResult AssembledSystem::ensure_pairs(const Model& model,
                                         const std::vector<ImplicitBodyContact::Pair>& pairs) {
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
  times_.factorization += seconds_since(start);
  return r;
}

StepResult AssembledSystem::rebuild_pattern(const Model& model) {
  std::vector<std::pair<int, int>> blocks = extra_blocks_;
  blocks.insert(blocks.end(), force_blocks_.begin(), force_blocks_.end());
  jacobian_.emplace(model, blocks);
  a_ = jacobian_->make_matrix();
  base_saved_ = false;
  return analyze();
}

void AssembledSystem::refresh_pair_terms(const ImplicitBodyContact& bodies, VecX& b) {
  Real* values = a_.valuePtr();
  const size_t nnz = static_cast<size_t>(a_.nonZeros());
  if (!base_saved_) {
    base_values_.assign(values, values + nnz);
    b_base_ = b;
    base_saved_ = true;
  } else {
    std::copy(base_values_.begin(), base_values_.end(), values);
    b = b_base_;
  }
  bodies.add_terms(a_, &b);
}

void AssembledSystem::unconstrain(const ImplicitContact& contacts) { contacts.unconstrain(a_); }

}  // namespace jelly
