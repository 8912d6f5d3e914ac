#pragma once
// The seed report's stability claims (docs/benchmarking.md, "Seed report claims") as a table: which
// integrators stay stable on the slope and the elevator with the report's own contact rules, at
// the seed parameters and dt = 0.001, 0.0027 and 1/60, and at ks = 2400, kd = 120; the time of
// divergence of those that do not; and a verdict on each claim. The rules run in both
// placements: seed_framework (inside every force evaluation, as the course framework the report
// was written on; the reproduction of its claims) and seed (once after each step).
#include <ostream>
#include <string>
#include <vector>

#include <jelly/bench/shard.hpp>
#include <jelly/bench/table.hpp>
#include <jelly/core/types.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly::bench {

struct SeedOptions {
  std::vector<std::string> integrators;  // empty: every registered integrator
  std::vector<ContactModel> contacts{ContactModel::kSeedFramework, ContactModel::kSeed};
  int n = 10;
  Real horizon = 6;  // s: the elevator's first cycle and the start of the second
  Real energy_tolerance = 1;
  Shard shard;
  std::ostream* progress = nullptr;  // one line per finished work item, when set
  void validate() const;
};

// Table "seed": one row per (contact model, configuration, scene, integrator); an integrator
// that cannot run seed_framework (implicit, adaptive) is "skipped_unsupported" there.
Table run_seed(const SeedOptions& options);

// Table "seed_claims": each claim of the report per contact model and scene, the survivors among
// the report's four
// methods (explicit_euler, midpoint, rk4, symplectic_euler = the report's "implicit Euler"), any
// other integrator that survives, and the verdict (confirmed, refuted, or incomplete when a
// needed run is missing).
Table seed_claims(const Table& seed);

}  // namespace jelly::bench
