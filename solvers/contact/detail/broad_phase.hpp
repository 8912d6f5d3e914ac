#pragma once
// The broad phase of particle-particle contact: a uniform grid of cells as large as the largest
// contact distance (a counting sort of the particles by cell: a dense grid over their bounding
// box, or a spatial hash of the cells when the box is sparse), rebuilt from scratch at every call.
// Its cost grows linearly with the number of particles; after the first call on a given number of
// particles it allocates nothing more.
#include <array>
#include <utility>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

class BroadPhase {
 public:
  using Pair = std::pair<int, int>;

  // Every pair i < j with |x_i - x_j| < radius_i + radius_j, each once, in an order that depends
  // only on the input (deterministic). `x` holds 3 coordinates per particle, `radius` one value
  // > 0 per particle. A dense grid over the bounding box when it has at most 8 cells per
  // particle (cache friendly), else the spatial hash.
  void find_pairs(const VecX& x, const VecX& radius, std::vector<Pair>& pairs);

 private:
  void find_pairs_dense(const VecX& x, const VecX& radius, const Eigen::Array3d& lo, Real inverse,
                        const Eigen::Array3i& dims, std::vector<Pair>& pairs);

  std::vector<Real> xs_, rs_;             // [3N], [N] positions and radii in the dense grid's order
  std::vector<int> start_;                // [buckets + 1] first sorted slot of each hash bucket
  std::vector<int> sorted_;               // [N] particles ordered by bucket
  std::vector<int> bucket_;               // [N] bucket of each particle
  std::vector<std::array<int, 3>> cell_;  // [N] cell of each particle
};

}  // namespace jelly
