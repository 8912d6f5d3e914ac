#pragma once
// Threads for the hot loops (docs/threads.md): OpenMP teams of a size given per call, a static
// split of index ranges, and sums whose value does not depend on the number of threads (fixed
// chunks whose partial sums are added in chunk order). Results of every loop built on these
// are the same bit for bit for any thread count.
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <jelly/core/types.hpp>

namespace jelly::parallel {

// The cores this process may run on (its CPU affinity mask), at least 1.
int available_cores();
// `requested` threads, or all available cores for 0 (the default of the `threads` options).
int resolve_threads(int requested);

// Below this many items a loop is not worth waking a second thread for.
constexpr long kMinItemsPerThread = 4096;
// The same for a loop over particles (about 3 vector entries and some arithmetic each).
constexpr long kMinParticlesPerThread = 1024;

// The number of threads to use for n items: at most `threads`, at least 1, and no more than
// one per kMinItemsPerThread items (`min_items`).
inline int team_size(int threads, long n, long min_items = kMinItemsPerThread) {
  const long useful = std::max<long>(1, n / std::max<long>(1, min_items));
  return static_cast<int>(std::max<long>(1, std::min<long>(threads, useful)));
}

// Part `part` of `parts` of [0, n): contiguous, in order, sizes differing by at most `align`
// (boundaries are multiples of `align`).
struct Range {
  long begin, end;
};
inline Range split(long n, int part, int parts, long align = 1) {
  const long units = (n + align - 1) / align;
  const long b = units * part / parts * align, e = units * (part + 1) / parts * align;
  return {std::min(b, n), std::min(e, n)};
}

// A split of [0, n) between a team's threads that follows how fast each thread got through its
// part last time: for a loop whose every item comes out the same whichever thread computes it
// (the force loop, the matrix-free product: each particle's sum in one fixed order), so that a
// thread that runs slower (on these virtual machines, often the one on CPU 0) does not keep the
// other waiting at the region's end. Each thread asks for its range and reports its time; after
// the region, update() moves the boundaries part of the way toward equal times. Not for
// concurrent regions on one object.
class BalancedSplit {
 public:
  // Part `part` of `parts` of [0, n).
  Range range(long n, int part, int parts) const;
  // At least the size of any part of n items among `parts` (no part is given more than 3/2 of
  // an equal share, + 2 items for rounding).
  static long largest(long n, int parts) { return (3 * n + 2 * parts - 1) / (2 * parts) + 2; }
  // The seconds `part` took for its range (each thread its own entry).
  void record(int part, double seconds);
  // After the region: the next split from the times recorded (a team of another size starts
  // from equal parts).
  void update(int parts);

 private:
  std::vector<double> share_;    // [parts]: the fraction of the items of each part
  std::vector<double> seconds_;  // [parts]: the last region's times
  bool equal_ = true;            // equal shares: split()'s ranges
};

// Runs body(part, parts) on a team of `threads` threads (inline when threads <= 1); `parts` is
// the size of the team OpenMP gave (it may give fewer threads than asked). `#pragma omp
// barrier` inside body synchronises the team.
template <class Body>
void run([[maybe_unused]] int threads, Body&& body) {
#ifdef _OPENMP
  if (threads > 1) {
#pragma omp parallel num_threads(threads)
    body(omp_get_thread_num(), omp_get_num_threads());
    return;
  }
#endif
  body(0, 1);
}

// body(begin, end) over a static split of [0, n) between up to `threads` threads, at
// multiples of `align` (3: a vector of 3 entries per particle, split as the particle loops are).
template <class Body>
void for_ranges(int threads, long n, Body&& body, long min_items = kMinItemsPerThread,
                long align = 1) {
  run(team_size(threads, n, min_items), [&](int part, int parts) {
    const Range r = split(n, part, parts, align);
    if (r.begin < r.end) body(r.begin, r.end);
  });
}

// to = from (resized when it differs in size), on up to `threads` threads split at multiples
// of 3 as the particle loops are split: each thread copies the particles it wrote.
void copy(int threads, const VecX& from, VecX& to);

// Sums of a fixed partition of [0, n) into chunks of kSumChunk items (one chunk when n is
// smaller), added in chunk order: the same value for any number of threads.
constexpr long kSumChunk = 8192;
inline long sum_chunks(long n) { return std::max<long>(1, (n + kSumChunk - 1) / kSumChunk); }

// The K sums of chunk_sums(begin, end) -> std::array<Real, K> over a fixed partition of [0, n)
// into chunks of `chunk` items (one chunk when n is smaller), each added in chunk order: the
// same values for any number of threads. `partials` is workspace (K per chunk; no allocation
// once it has that size).
template <std::size_t K, class ChunkSums>
std::array<Real, K> ordered_sums(int threads, long n, long chunk, std::vector<Real>& partials,
                                 ChunkSums&& chunk_sums) {
  const long chunks = std::max<long>(1, (n + chunk - 1) / chunk);
  if (static_cast<long>(partials.size()) != static_cast<long>(K) * chunks)
    partials.assign(K * chunks, 0.0);
  // A thread per chunk, and no more than one per kMinItemsPerThread items.
  run(std::min(team_size(threads, chunks, 1), team_size(threads, n)), [&](int part, int parts) {
    const Range r = split(chunks, part, parts);
    for (long c = r.begin; c < r.end; ++c) {
      const std::array<Real, K> s = chunk_sums(c * chunk, std::min(n, (c + 1) * chunk));
      std::copy(s.begin(), s.end(), partials.begin() + K * c);
    }
  });
  std::array<Real, K> total{};
  for (long c = 0; c < chunks; ++c)
    for (std::size_t k = 0; k < K; ++k) total[k] += partials[K * c + k];
  return total;
}

// The sum over chunks of `chunk` items of chunk_sum(begin, end) (ordered_sums with one sum).
template <class ChunkSum>
Real ordered_sum(int threads, long n, std::vector<Real>& partials, ChunkSum&& chunk_sum,
                 long chunk = kSumChunk) {
  return ordered_sums<1>(threads, n, chunk, partials, [&](long begin, long end) {
    return std::array<Real, 1>{chunk_sum(begin, end)};
  })[0];
}

// Keeps libraries that start their own threads (OpenMP regions inside CHOLMOD, which asks for
// a fixed team of 4; OpenBLAS's thread pool) on the calling thread while alive: their threads
// spin after each call and did not shorten the wall time (docs/threads.md).
class SerialLibraries {
 public:
  SerialLibraries();
  ~SerialLibraries();
  SerialLibraries(const SerialLibraries&) = delete;
  SerialLibraries& operator=(const SerialLibraries&) = delete;

 private:
  int saved_levels_ = -1;
  int saved_blas_ = 0;
};

// Sets OpenBLAS's thread count when libjelly runs with OpenBLAS (no effect otherwise).
void set_blas_threads(int threads);

}  // namespace jelly::parallel
