#include <jelly/solvers/run_report.hpp>

#include <cmath>
#include <limits>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/detail/run_fields.hpp>

namespace jelly {

namespace {

void check_max_energy(const DivergenceGuard& g, const std::string& prefix) {
  require(!std::isnan(g.max_energy), prefix + "max_energy", g.max_energy,
          "an energy in J (infinite = not checked)");
}

}  // namespace

const FieldTable<DivergenceGuard>& divergence_fields() {
  using G = DivergenceGuard;
  static const FieldTable<G> table{
      "DivergenceGuard",
      "divergence",
      "What counts as diverged: a run that passes a limit stops with status diverged",
      {
          number_field<&G::max_speed>("max_speed", "m/s", range_or_infinite(range_above(0)),
                                      "a speed > 0 m/s", "A faster particle stops the run"),
          number_field<&G::max_distance>("max_distance", "m", range_or_infinite(range_above(0)),
                                         "a distance > 0 m",
                                         "A particle farther from the origin stops the run"),
      },
      &check_max_energy,
  };
  return table;
}

void DivergenceGuard::validate() const {
  validate_fields(divergence_fields(), *this, "divergence.");
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
