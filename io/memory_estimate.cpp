#include <jelly/io/detail/memory_estimate.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace jelly {

double estimate_memory_bytes(std::int64_t particles, std::int64_t springs,
                             const std::string& integrator, bool recording) {
  // The constants are fitted to the peak resident sizes of `jelly run` (Release, /usr/bin/time
  // -f %M, scripts/memory_figures.py) per integrator with its default options, on cubes, a cloth
  // and a tet body at two sizes each: an estimate of the order of the peak (within a factor of
  // 2, tests/io/memory_estimate_test.cpp), used to refuse runs that cannot fit, not a bound.
  const double n = static_cast<double>(particles);
  const double m = static_cast<double>(springs);
  double per_particle = 300;  // state, masses, work vectors of the integrator
  double per_spring = 80;     // the springs' arrays and the force loop's bands
  double fill = 0;            // a sparse Cholesky factor's entries beyond the matrix's own
  if (integrator == "implicit_euler") {
    per_particle += 550;  // CG's vectors and the block-Jacobi blocks (cg above 1000 unknowns)
  } else if (integrator.rfind("arkode_dirk", 0) == 0) {
    per_spring += 450;  // the Newton matrix's blocks, its pattern and the linear solver's copy
  } else if (integrator.rfind("arkode", 0) == 0) {
    per_particle += 875;  // ARKODE's stage and work vectors
  } else if (integrator == "xpbd") {
    per_spring += 90;  // the constraints' multipliers, colours and gradients
  } else if (integrator == "projective_dynamics") {
    // One prefactored matrix with a particle's springs as its row: a nested-dissection factor of
    // a 3D body holds about (springs) x (particles)^(1/3) entries (a sheet fewer, about half at
    // the sizes measured).
    fill = 16 * m * std::cbrt(n);
  }
  if (recording) per_particle += 3500;
  constexpr double kBase = 20e6;  // the program and its libraries
  return kBase + per_particle * n + per_spring * m + fill;
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  if (!in) return -1;
  double available = -1, swap = 0;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string key;
    double kib = 0;
    fields >> key >> kib;
    if (key == "MemAvailable:") available = kib * 1024;
    if (key == "SwapFree:") swap = kib * 1024;
  }
  return available < 0 ? -1 : available + swap;
}

std::string bytes_text(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1000 && u < 5) {
    bytes /= 1000;
    ++u;
  }
  char text[32];
  std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
  return text;
}

}  // namespace jelly
