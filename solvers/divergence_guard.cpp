#include <jelly/solvers/divergence_guard.hpp>

#include <cmath>
#include <limits>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>

namespace jelly {

void DivergenceGuard::validate() const {
  require(max_speed > 0, "divergence.max_speed", max_speed, "a speed > 0 m/s");
  require(max_distance > 0, "divergence.max_distance", max_distance, "a distance > 0 m");
  require(!std::isnan(max_energy), "divergence.max_energy", max_energy,
          "an energy in J (infinite = not checked)");
}

std::optional<std::string> DivergenceGuard::check(const State& s, int threads) const {
  const int n = static_cast<int>(s.x.size() / 3);
  const Real speed2 = max_speed * max_speed;
  const Real dist2 = max_distance * max_distance;
  // One branch-free (vectorised) pass first: every step of every run is checked, and nearly
  // all of them pass. Anything it flags (a limit, or a non-finite or overflowing square) goes to
  // the particle by particle loop below, which decides and names the particle.
  const Real* px = s.x.data();
  const Real* pv = s.v.data();
  // A little below the limits: these sums may round differently from squaredNorm's below.
  const Real speed2_low = speed2 * (1 - 8 * std::numeric_limits<Real>::epsilon());
  const Real dist2_low = dist2 * (1 - 8 * std::numeric_limits<Real>::epsilon());
  // (On the threads of the step, over the same particle ranges as the step's loops: each
  // thread reads what it wrote.)
  bool flagged = false;
  parallel::for_ranges(
      threads, n,
      [&](long begin, long end) {
        bool mine = false;
        for (long i = begin; i < end; ++i) {
          const Real v2 =
              pv[3 * i] * pv[3 * i] + pv[3 * i + 1] * pv[3 * i + 1] + pv[3 * i + 2] * pv[3 * i + 2];
          const Real x2 =
              px[3 * i] * px[3 * i] + px[3 * i + 1] * px[3 * i + 1] + px[3 * i + 2] * px[3 * i + 2];
          mine |= !(v2 <= speed2_low && x2 <= dist2_low && std::isfinite(v2) && std::isfinite(x2));
        }
        if (mine) {
#pragma omp atomic write
          flagged = true;
        }
      },
      parallel::kMinParticlesPerThread);
  if (!flagged) return std::nullopt;
  for (int i = 0; i < n; ++i) {
    const auto x = particle(s.x, i);
    const auto v = particle(s.v, i);
    if (!x.allFinite() || !v.allFinite()) {
      return "particle " + std::to_string(i) + " has a non-finite position or velocity";
    }
    if (v.squaredNorm() > speed2) {
      return "particle " + std::to_string(i) + " moves at " + to_text(v.norm()) +
             " m/s, above the limit of " + to_text(max_speed) + " m/s";
    }
    if (x.squaredNorm() > dist2) {
      return "particle " + std::to_string(i) + " is " + to_text(x.norm()) +
             " m from the origin, beyond the limit of " + to_text(max_distance) + " m";
    }
  }
  return std::nullopt;
}

std::optional<std::string> DivergenceGuard::check(const Model& model, const State& s,
                                                  int threads) const {
  if (auto why = check(s, threads)) return why;
  if (std::isfinite(max_energy)) {
    const Real e = total_energy(model, s);
    if (!(e <= max_energy)) {
      return "total energy " + to_text(e) + " J is above the cap of " + to_text(max_energy) + " J";
    }
  }
  return std::nullopt;
}

}  // namespace jelly
