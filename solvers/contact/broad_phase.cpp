#include <jelly/solvers/contact/detail/broad_phase.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace jelly {

namespace {

// Teschner et al. 2003's spatial hash of a cell, into a power-of-two table (mask = size - 1).
int hash_cell(int cx, int cy, int cz, unsigned mask) {
  const unsigned h = (static_cast<unsigned>(cx) * 73856093u) ^
                     (static_cast<unsigned>(cy) * 19349663u) ^
                     (static_cast<unsigned>(cz) * 83492791u);
  return static_cast<int>(h & mask);
}

// The cell of a coordinate (in cells), clamped to +-2^30 so that a huge, infinite or NaN
// coordinate (a diverging run, a damaged checkpoint) has a cell too: converting those to int was
// undefined (found by jelly_checkpoint_fuzzer). Far particles share the clamped cells, and the
// distance test keeps them apart.
int cell_index(Real coordinate) {
  constexpr Real kLimit = Real(1 << 30);
  const Real c = std::floor(coordinate);
  if (!(c > -kLimit)) return -(1 << 30);
  return c < kLimit ? static_cast<int>(c) : (1 << 30);
}

}  // namespace

void BroadPhase::find_pairs(const VecX& x, const VecX& radius, std::vector<Pair>& pairs) {
  pairs.clear();
  const int n = static_cast<int>(radius.size());
  if (n < 2) return;
  // Cells as large as the largest contact distance: a pair in contact lies in neighbouring cells.
  const Real cell = 2 * radius.maxCoeff();
  if (!(cell > 0)) return;  // no particle reaches another
  const Real inverse = 1 / cell;
  // A dense grid over the particles' bounding box (one more cell on every side) when it has at
  // most 8 cells per particle: neighbouring cells along x are neighbours in memory. Else a hash.
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<Real>::infinity());
  Eigen::Array3d hi = -lo;
  bool finite = true;  // a NaN coordinate would not widen the box: the hash's clamped cells
  for (int i = 0; i < n; ++i) {
    const Eigen::Array3d p(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    finite = finite && p.allFinite();
    lo = lo.min(p);
    hi = hi.max(p);
  }
  const Eigen::Array3d span = ((hi - lo) * inverse).floor() + 3;
  if (finite && span.allFinite() && span.prod() <= 8.0 * n + 64) {
    find_pairs_dense(x, radius, lo, inverse, span.cast<int>(), pairs);
    return;
  }
  unsigned buckets = 1;
  while (buckets < 2u * static_cast<unsigned>(n)) buckets <<= 1;
  const unsigned mask = buckets - 1;
  start_.assign(buckets + 1, 0);
  sorted_.resize(n);
  bucket_.resize(n);
  cell_.resize(n);
  for (int i = 0; i < n; ++i) {
    std::array<int, 3>& c = cell_[i];
    for (int a = 0; a < 3; ++a) c[a] = cell_index(x[3 * i + a] * inverse);
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

void BroadPhase::find_pairs_dense(const VecX& x, const VecX& radius, const Eigen::Array3d& lo,
                                  Real inverse, const Eigen::Array3i& dims,
                                  std::vector<Pair>& pairs) {
  const int n = static_cast<int>(radius.size());
  const int nx = dims[0], nxy = dims[0] * dims[1];
  const int cells = nxy * dims[2];
  start_.assign(cells + 1, 0);
  sorted_.resize(n);
  bucket_.resize(n);
  for (int i = 0; i < n; ++i) {
    // Cell coordinates from 1 (cell 0 and the last are the padding).
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = 1 + static_cast<int>(std::floor((x[3 * i + a] - lo[a]) * inverse));
    bucket_[i] = c[0] + nx * c[1] + nxy * c[2];
    ++start_[bucket_[i] + 1];
  }
  for (int b = 0; b < cells; ++b) start_[b + 1] += start_[b];
  for (int i = 0; i < n; ++i) sorted_[start_[bucket_[i]]++] = i;
  for (int b = cells; b > 0; --b) start_[b] = start_[b - 1];
  start_[0] = 0;
  // Positions and radii in the sorted order, for locality.
  xs_.resize(3 * n);
  rs_.resize(n);
  for (int s = 0; s < n; ++s) {
    const int i = sorted_[s];
    for (int a = 0; a < 3; ++a) xs_[3 * s + a] = x[3 * i + a];
    rs_[s] = radius[i];
  }
  // Each pair once: particle s meets the particles after it in the sorted order, which lie in
  // its own row of cells (from s + 1) and in the 4 rows after it (dz = 0, dy = 1 and dz = 1,
  // dy = -1..1); the 4 rows before hold none.
  constexpr int kRows = 5;
  const int row_offset[kRows] = {0, nx, nxy - nx, nxy, nxy + nx};
  for (int s = 0; s < n; ++s) {
    const int c = bucket_[sorted_[s]];
    const Real px = xs_[3 * s], py = xs_[3 * s + 1], pz = xs_[3 * s + 2], r = rs_[s];
    for (int k = 0; k < kRows; ++k) {
      const int row = c + row_offset[k];  // cells row - 1 .. row + 1 are contiguous
      const int end = start_[row + 2];
      for (int t = std::max(start_[row - 1], s + 1); t < end; ++t) {
        const Real ex = xs_[3 * t] - px, ey = xs_[3 * t + 1] - py, ez = xs_[3 * t + 2] - pz;
        const Real reach = r + rs_[t];
        if (ex * ex + ey * ey + ez * ez < reach * reach) {
          const int i = sorted_[s], j = sorted_[t];
          pairs.emplace_back(std::min(i, j), std::max(i, j));
        }
      }
    }
  }
}

}  // namespace jelly
