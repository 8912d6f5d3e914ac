#pragma once
// Cost per step against the cube size for each integrator, on the seed slope with every contact
// active (or on scene files): the step split into the integrator (of which force evaluations) and
// contact, the integrator's own statistics (assembly, factorisation, solve when it reports them),
// springs per second and the peak resident memory of each configuration (memory.hpp).
#include <string>
#include <vector>

#include <jelly/bench/shard.hpp>
#include <jelly/bench/table.hpp>
#include <jelly/core/types.hpp>

namespace jelly::bench {

// The --preconditioners value that runs implicit_euler with CHOLMOD instead of CG.
inline constexpr const char* kDirectCholmod = "direct";
// The --preconditioners value that runs cg_preconditioner "amg" with amg_cycle "v".
inline constexpr const char* kAmgVCycle = "amg_v";

struct SpeedOptions {
  std::vector<std::string> integrators;  // empty: every registered integrator
  std::vector<int> sizes{5, 10, 20, 30};
  // Scene files measured instead of the slope's cubes (sizes then unused): their bodies
  // (lowered onto the first terrain, as the cubes are, when there is one), terrains and
  // integrator options (cg_preconditioner replaced by each of `preconditioners`), stepped at
  // dt; rows labelled "integrator[preconditioner]@file stem", n = the scene's index.
  std::vector<std::string> scenes;
  // implicit_euler's cg_preconditioner values, a row each (labelled "implicit_euler[name]"),
  // kDirectCholmod for its linear_solver "cholmod" (a factorization every step) and kAmgVCycle
  // for amg with amg_cycle "v"; empty: its default only.
  std::vector<std::string> preconditioners;
  Real ks = 1400;  // N/m, every spring type (kd stays the seed's 50)
  // Thread counts, each a row (the scaling table); 0 = all cores.
  std::vector<int> threads{0};
  Real dt = 1e-3;
  int warmup_steps = 20;
  int steps = 200;
  // Run the thread counts of each integrator and size in alternation, `interleave_block` steps
  // each in turn, so that a change of the machine's speed during the measurement falls on all of
  // them alike (the scaling table). Their scenes are then in memory together: the peak memory
  // is the process's peak so far (memory_per_configuration 0).
  bool interleave = false;
  int interleave_block = 20;
  Shard shard;
  void validate() const;
};

// Tables "speed" (one row per integrator and size) and "speed_statistics" (every counter of the
// integrator's statistics() after the timed steps, long format: one row per key).
std::vector<Table> run_speed(const SpeedOptions& options);

}  // namespace jelly::bench
