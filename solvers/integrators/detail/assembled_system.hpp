#pragma once
// The backward-Euler system as a sparse matrix (the springs' 3x3 blocks, the blocks of contact
// pairs between bodies and of added forces' Jacobians) for CHOLMOD, LDLT or CG. Its pattern and
// symbolic analysis are built once and again only when a block is new.
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/force.hpp>
#include <jelly/solvers/contact/detail/implicit_body_contact.hpp>
#include <jelly/solvers/integrators/detail/backward_euler_system.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>

namespace jelly {

class AssembledSystem final : public BackwardEulerSystem {
 public:
  // The pattern of `model`'s springs and `solver`'s symbolic analysis of it; call analyze()
  // before the first assembly. `automatic`: the options' linear_solver was "auto" (its CG is
  // block Jacobi).
  AssembledSystem(const Model& model, ImplicitLinearSolver solver, bool automatic,
                  const ImplicitEulerOptions& options, SystemTimes& times);
  // The symbolic analysis of the pattern.
  StepResult analyze();
  // Whether the pattern is the one of `model`'s springs.
  bool fits(const Model& model) const;

  std::string_view name() const override { return solver_->name(); }
  int rows() const override { return jacobian_->rows(); }
  void set_threads(int threads) override;
  void invalidate() override { solver_->invalidate(); }
  bool assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real h, VecX& kw) override;
  void add_diagonal(int particle, Real value) override;
  void constrain(ImplicitContact& contacts, const VecX& b, bool prescribe, VecX& rhs, VecX& z,
                 VecX& guess) override;
  bool update_contacts(ImplicitContact& contacts, const Terrains& terrains, const VecX& b,
                       const VecX& dv, bool commit, bool screening) override;
  LinearResult solve(const VecX& b, VecX& y, ImplicitContact* constraints, Real tolerance,
                     bool resume) override;

  // The added forces' Jacobian blocks, and their blocks in the pattern (a new symbolic
  // analysis only when a block is new).
  StepResult collect_force_jacobians(const Dynamics& dynamics, const VecX& x, const VecX& v,
                                     Real t) override;
  // Whether the last collect_force_jacobians() found blocks.
  bool has_force_terms() const override { return !force_jacobian_.empty(); }

  // Contact pairs between bodies inside the solve: the pattern holds the blocks of `pairs` (the
  // union of the candidates seen so far; a new symbolic analysis only when a pair is new).
  StepResult ensure_pairs(const Model& model, const std::vector<ImplicitBodyContact::Pair>& pairs);
  // The next refresh_pair_terms() saves the assembly first (a new assembly was made).
  void forget_saved_assembly() { base_saved_ = false; }
  // A and b = the saved assembly plus the active pairs' terms (saves the assembly first).
  void refresh_pair_terms(const ImplicitBodyContact& bodies, VecX& b);
  // A += the active pairs' terms.
  void add_pair_terms(const ImplicitBodyContact& bodies) { bodies.add_terms(a_, nullptr); }
  // Undoes the contact filter of A (before the pairs' terms change).
  void unconstrain(const ImplicitContact& contacts);

  const LinearSolverCounters& counters() const { return solver_->counters(); }
  // The amg preconditioner's levels (0: another solver) and hierarchies built or refreshed.
  int multigrid_levels() const { return cg_ != nullptr ? cg_->multigrid_levels() : 0; }
  long preconditioner_refreshes() const {
    return cg_ != nullptr ? cg_->preconditioner_factorizations() : 0;
  }

 private:
  // The pattern of a_: the springs' blocks, the pairs' and the forces'; analysed again.
  StepResult rebuild_pattern(const Model& model);

  JacobianOptions jacobian_options_;
  std::optional<SpringJacobian> jacobian_;
  std::unique_ptr<LinearSolver> solver_;
  CgSolver* cg_ = nullptr;  // solver_ when it is CG (amg reads the positions)
  SparseMatrix a_;
  SystemTimes& times_;
  int threads_ = 1;
  std::vector<std::pair<int, int>> extra_blocks_;  // pair blocks in jacobian_'s pattern
  ForceJacobian force_jacobian_;                   // the added forces' blocks of this assembly
  std::vector<std::pair<int, int>> force_blocks_;  // their off-diagonal blocks in the pattern
  bool base_saved_ = false;                        // base_values_ / b_base_ hold this assembly
  std::vector<Real> base_values_;
  VecX b_base_;
};

}  // namespace jelly
