#pragma once
// The broad phase of particle-particle contact: a uniform grid of cells as large as the largest
// contact distance, stored as a spatial hash (counting sort of the particles by the hash of
// their cell), rebuilt from scratch at every call. Its cost grows linearly with the number of
// particles; after the first call on a given number of particles it allocates nothing more.
#include <array>
#include <utility>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

class BroadPhase {
 public:
  using Pair = std::pair<int, int>;

  // Every pair i < j with |x_i - x_j| < radius_i + radius_j, in increasing i then in the order
  // of the cells and the sort (deterministic: the same input gives the same list). `x` holds
  // 3 coordinates per particle, `radius` one value > 0 per particle.
  void find_pairs(const VecX& x, const VecX& radius, std::vector<Pair>& pairs);

 private:
  std::vector<int> start_;                // [buckets + 1] first sorted slot of each hash bucket
  std::vector<int> sorted_;               // [N] particles ordered by bucket
  std::vector<int> bucket_;               // [N] bucket of each particle
  std::vector<std::array<int, 3>> cell_;  // [N] cell of each particle
};

}  // namespace jelly
