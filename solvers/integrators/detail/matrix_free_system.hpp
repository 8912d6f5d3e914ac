#pragma once
// The backward-Euler system without a matrix: A's blocks per spring in the springs' bands
// (core/detail/band_system.hpp), solved by CG preconditioned by block Jacobi or by a lattice
// multigrid V-cycle. Only for models whose springs fill the bands, without contact pairs
// between bodies in the solve. Added forces' Jacobian blocks (off the bands) are kept per row
// beside them (BandSystem::set_extra_blocks); the multigrid's coarse levels leave them out (a
// preconditioner: its fine level and the CG products have them).
#include <optional>
#include <utility>
#include <vector>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/solvers/integrators/detail/backward_euler_system.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/solvers/linear/detail/lattice_multigrid.hpp>

namespace jelly {

class MatrixFreeSystem final : public BackwardEulerSystem {
 public:
  MatrixFreeSystem(const ImplicitEulerOptions& options, SystemTimes& times);

  // Builds the system on `bands` of `model` (and the multigrid hierarchy when the options ask
  // for it and the model has a lattice body).
  void build(const Model& model, const SpringBands& bands);
  // Frees the system (the assembled system takes over); the counters stay.
  void release();
  // Whether the system is built, on `bands` and for `dofs` unknowns.
  bool built_for(const SpringBands& bands, int dofs) const {
    return band_.has_value() && band_->built_for(bands) && band_->rows() == dofs;
  }
  bool built() const { return band_.has_value(); }
  // The coarse operators of the multigrid are rebuilt at the next solve (a restored state).
  void mark_coarse_stale() { coarse_stale_ = true; }
  bool uses_multigrid() const { return use_multigrid_; }
  int multigrid_levels() const { return multigrid_.levels(); }
  const LinearSolverCounters& counters() const { return cg_.counters(); }

  std::string_view name() const override;
  int rows() const override { return band_->rows(); }
  void set_threads(int threads) override { threads_ = threads; }
  void invalidate() override { coarse_stale_ = true; }
  StepResult collect_force_jacobians(const Dynamics& dynamics, const VecX& x, const VecX& v,
                                     Real t) override;
  bool has_force_terms() const override { return !force_jacobian_.empty(); }
  bool assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real h, VecX& kw) override;
  void add_diagonal(int particle, Real value) override { band_->add_diagonal(particle, value); }
  void constrain(ImplicitContact& contacts, const VecX& b, bool prescribe, VecX& rhs, VecX& z,
                 VecX& guess) override;
  bool update_contacts(ImplicitContact& contacts, const Terrains& terrains, const VecX& b,
                       const VecX& dv, bool commit, bool screening) override;
  LinearResult solve(const VecX& b, VecX& y, ImplicitContact* constraints, Real tolerance,
                     bool resume) override;

 private:
  const ImplicitEulerOptions& options_;
  SystemTimes& times_;
  int threads_ = 1;
  std::optional<BandSystem> band_;
  MatrixFreeCg cg_;
  // cg_preconditioner = multigrid, when the model has a lattice body: the V-cycle, and whether
  // its coarse operators are older than the last assembly.
  LatticeMultigrid multigrid_;
  bool use_multigrid_ = false;
  bool coarse_stale_ = true;
  int coarse_age_ = 0;          // assemblies since the coarse operators were built
  int coarse_iterations_ = -1;  // CG iterations of the first solve with them (-1: none yet)
  // The contacts (particle, stick or slide) the coarse operators were built with: those of
  // another set are far from its operator (a released contact's coupling is missing from
  // them), so a solve with another set rebuilds them.
  std::vector<std::pair<int, int>> coarse_contacts_, contacts_now_;
  ForceJacobian force_jacobian_;  // the added forces' blocks for the next assembly
  VecX az_;
  VecX cg_x_;                      // a loose solve's iterate, for resuming it
  int loose_iterations_ = 0;       // ... and its CG iterations
  std::vector<int> contact_rows_;  // the contacts' particles, for their rows of A dv
};

}  // namespace jelly
