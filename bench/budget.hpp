#pragma once
// Which integrator for a frame budget: the seed cube (n per edge) falling onto the seed slope
// (coulomb contact), and optionally the cloth of scenes/cloth_on_sphere.json (nu = nv = n)
// falling over its sphere, advanced frame by frame (1/60 s) by each setup (an integrator, its
// options and its steps per frame). Per scene, size and setup: the cost of one frame (median
// over the run), the error against a tight RK4 reference, the energy behaviour, the fewest steps
// per frame that are stable at the seed material, and (cubes) the stiffest ks of a ladder that
// stays stable at the setup's steps per frame (docs/benchmarking.md).
#include <ostream>
#include <string>
#include <vector>

#include <jelly/bench/shard.hpp>
#include <jelly/bench/table.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly::bench {

struct BudgetSetup {
  std::string label;  // unique, e.g. "xpbd s10"
  std::string integrator;
  IntegratorOptions options;
  int steps_per_frame = 0;  // 0: the fewest stable ones at the seed material (searched)
};

// symplectic_euler and rk4 (steps per frame searched), implicit_euler, projective_dynamics
// (5, 10 and 20 iterations, 10 with Chebyshev), xpbd (1, 5 and 20 substeps) and vbd (10 sweeps,
// contact_hardness 100), one step per frame each.
std::vector<BudgetSetup> default_budget_setups();

struct BudgetOptions {
  std::vector<int> sizes{10, 20, 40};
  // Cloths measured after the cubes: scenes_dir/cloth_on_sphere.json with nu = nv = each size
  // (empty: none). The ks ladder is not searched for them (stiffest_ks is NAN).
  std::vector<int> cloth_sizes;
  std::string scenes_dir;           // the folder of cloth_on_sphere.json
  std::vector<BudgetSetup> setups;  // empty: default_budget_setups()
  std::vector<std::string> labels;  // only the setups with these labels (empty: all)
  Real frame = 1.0 / 60;            // s
  Real horizon = 2;                 // s of simulation measured per setup
  bool lowered = false;             // start 0.1 m above the slope instead of the seed pose
  Real ks = 1400, kd = 50;          // the seed material of the measured runs
  // Runs of the searches (fewest steps per frame, stiffest ks): this long, stopped by the
  // divergence guard with the stability command's energy cap.
  Real search_horizon = 1.5;
  std::vector<int> steps_ladder{1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
  std::vector<Real> ks_ladder{1400, 5600, 22400, 89600, 358400, 1433600};  // kd = ks 50 / 1400
  int ks_search_max_n = 40;            // sizes above this skip the ks ladder
  int reference_steps_per_frame = 16;  // RK4 at frame / this
  int sample_every = 6;                // frames between position-error samples
  Shard shard;
  std::ostream* progress = nullptr;  // one line per finished work item, when set
  void validate() const;
};

// Table "budget": one row per (scene, size, setup) work item owned by the shard.
Table run_budget(const BudgetOptions& options);

}  // namespace jelly::bench
