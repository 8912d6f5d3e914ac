#include <jelly/io/memory_estimate.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace jelly {

double estimate_memory_bytes(std::int64_t particles, std::int64_t springs,
                             const std::string& integrator, bool recording) {
  // The constants are fitted to the peak resident sizes of `jelly run` (Release, /usr/bin/time
  // -f %M) on the seed slope at several sizes, per integrator and with a recorder: an estimate of
  // the order of the peak, used to refuse runs that cannot fit, not a bound.
  const double n = static_cast<double>(particles);
  const double m = static_cast<double>(springs);
  double per_particle = 300;  // state, masses, work vectors of the integrator
  double per_spring = 80;     // the springs' arrays and the force loop's bands
  if (integrator == "implicit_euler" || integrator.rfind("arkode_dirk", 0) == 0) {
    per_spring += 550;  // the Jacobians' blocks, their pattern and the linear solver's matrix
  }
  if (recording) per_particle += 3500;
  constexpr double kBase = 20e6;  // the program and its libraries
  return kBase + per_particle * n + per_spring * m;
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
