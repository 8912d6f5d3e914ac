#include <jelly/core/detail/parallel.hpp>

#include <dlfcn.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <thread>

namespace jelly::parallel {

int available_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int count = CPU_COUNT(&set);
    if (count > 0) return count;
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

int resolve_threads(int requested) { return requested > 0 ? requested : available_cores(); }

void copy(int threads, const VecX& from, VecX& to) {
  if (to.size() != from.size()) to.resize(from.size());
  const Real* src = from.data();
  Real* dst = to.data();
  for_ranges(
      threads, from.size(),
      [&](long begin, long end) { std::copy(src + begin, src + end, dst + begin); },
      kMinItemsPerThread, 3);
}

Range BalancedSplit::range(long n, int part, int parts) const {
  if (equal_ || static_cast<int>(share_.size()) != parts) return split(n, part, parts);
  double before = 0;
  for (int k = 0; k < part; ++k) before += share_[k];
  const auto boundary = [&](double fraction) {
    return std::min(n, std::max(0L, std::lround(fraction * static_cast<double>(n))));
  };
  return {part == 0 ? 0 : boundary(before),
          part == parts - 1 ? n : boundary(before + share_[part])};
}

void BalancedSplit::record(int part, double seconds) {
  if (part < static_cast<int>(seconds_.size())) seconds_[part] = seconds;
}

void BalancedSplit::update(int parts) {
  if (static_cast<int>(share_.size()) != parts) {
    share_.assign(parts, 1.0 / parts);
    seconds_.assign(parts, 0.0);
    equal_ = true;
    return;
  }
  // The shares that would have taken equal times (each part's speed: its share per second).
  double total = 0;
  for (int k = 0; k < parts; ++k) {
    if (!(seconds_[k] > 0) || !std::isfinite(seconds_[k])) return;
    total += share_[k] / seconds_[k];
  }
  // Halfway there, or less where a share would leave [1/2, 3/2] of an equal share: the shares
  // still add up to 1.
  const double lo = 0.5 / parts, hi = 1.5 / parts;
  double step = 0.5;
  for (int k = 0; k < parts; ++k) {
    const double move = share_[k] / seconds_[k] / total - share_[k];
    if (move > 0) step = std::min(step, (hi - share_[k]) / move);
    if (move < 0) step = std::min(step, (share_[k] - lo) / -move);
  }
  step = std::max(0.0, step);
  equal_ = false;
  for (int k = 0; k < parts; ++k) share_[k] += step * (share_[k] / seconds_[k] / total - share_[k]);
}

namespace {

// OpenBLAS's thread-count functions, when libjelly runs with OpenBLAS (looked up, not linked:
// the BLAS is whichever libblas.so.3 the system provides).
struct OpenBlas {
  void (*set)(int) = nullptr;
  int (*get)() = nullptr;
  OpenBlas() {
    void* handle = RTLD_DEFAULT;
    set = reinterpret_cast<void (*)(int)>(dlsym(handle, "openblas_set_num_threads"));
    get = reinterpret_cast<int (*)()>(dlsym(handle, "openblas_get_num_threads"));
    for (const char* name : {"libopenblas.so.0", "libblas.so.3"}) {
      if (set != nullptr && get != nullptr) break;
      handle = dlopen(name, RTLD_NOW | RTLD_NOLOAD);  // only if already loaded
      if (handle == nullptr) continue;
      set = reinterpret_cast<void (*)(int)>(dlsym(handle, "openblas_set_num_threads"));
      get = reinterpret_cast<int (*)()>(dlsym(handle, "openblas_get_num_threads"));
    }
    if (set == nullptr || get == nullptr) set = nullptr, get = nullptr;
  }
};

const OpenBlas& openblas() {
  static const OpenBlas blas;
  return blas;
}

}  // namespace

void set_blas_threads(int threads) {
  if (openblas().set) openblas().set(std::max(1, threads));
}

SerialLibraries::SerialLibraries() {
  if (openblas().get) {
    saved_blas_ = openblas().get();
    if (saved_blas_ != 1) openblas().set(1);
  }
#ifdef _OPENMP
  // A region started while max-active-levels is 0 gets a team of one: no thread is woken.
  saved_levels_ = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
#endif
}

SerialLibraries::~SerialLibraries() {
  if (saved_blas_ > 1) openblas().set(saved_blas_);
#ifdef _OPENMP
  omp_set_max_active_levels(saved_levels_);
#endif
}

}  // namespace jelly::parallel
