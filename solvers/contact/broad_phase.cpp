#include <jelly/solvers/contact/broad_phase.hpp>

#include <algorithm>
#include <cmath>

namespace jelly {

namespace {

// Teschner et al. 2003's spatial hash of a cell, into a power-of-two table (mask = size - 1).
int hash_cell(int cx, int cy, int cz, unsigned mask) {
  const unsigned h = (static_cast<unsigned>(cx) * 73856093u) ^
                     (static_cast<unsigned>(cy) * 19349663u) ^
                     (static_cast<unsigned>(cz) * 83492791u);
  return static_cast<int>(h & mask);
}

}  // namespace

void BroadPhase::find_pairs(const VecX& x, const VecX& radius, std::vector<Pair>& pairs) {
  pairs.clear();
  const int n = static_cast<int>(radius.size());
  if (n < 2) return;
  // Cells as large as the largest contact distance: a pair in contact lies in neighbouring cells.
  const Real cell = 2 * radius.maxCoeff();
  const Real inverse = 1 / cell;
  unsigned buckets = 1;
  while (buckets < 2u * static_cast<unsigned>(n)) buckets <<= 1;
  const unsigned mask = buckets - 1;
  start_.assign(buckets + 1, 0);
  sorted_.resize(n);
  bucket_.resize(n);
  cell_.resize(n);
  for (int i = 0; i < n; ++i) {
    std::array<int, 3>& c = cell_[i];
    for (int a = 0; a < 3; ++a) c[a] = static_cast<int>(std::floor(x[3 * i + a] * inverse));
    bucket_[i] = hash_cell(c[0], c[1], c[2], mask);
    ++start_[bucket_[i] + 1];
  }
  for (unsigned b = 0; b < buckets; ++b) start_[b + 1] += start_[b];
  // Counting sort (stable: particles of a bucket in increasing index).
  for (int i = 0; i < n; ++i) sorted_[start_[bucket_[i]]++] = i;
  for (unsigned b = buckets; b > 0; --b) start_[b] = start_[b - 1];
  start_[0] = 0;

  for (int i = 0; i < n; ++i) {
    const std::array<int, 3>& c = cell_[i];
    const Vec3 xi(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    const Real ri = radius[i];
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          const int b = hash_cell(cx, cy, cz, mask);
          for (int s = start_[b]; s < start_[b + 1]; ++s) {
            const int j = sorted_[s];
            if (j <= i) continue;
            // Another cell of the same bucket is visited under its own offset: skip it here.
            const std::array<int, 3>& cj = cell_[j];
            if (cj[0] != cx || cj[1] != cy || cj[2] != cz) continue;
            const Real reach = ri + radius[j];
            const Vec3 d(x[3 * j] - xi[0], x[3 * j + 1] - xi[1], x[3 * j + 2] - xi[2]);
            if (d.squaredNorm() < reach * reach) pairs.emplace_back(i, j);
          }
        }
      }
    }
  }
}

}  // namespace jelly
