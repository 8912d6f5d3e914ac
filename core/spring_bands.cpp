#include <jelly/core/detail/spring_bands.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>

#include <jelly/core/detail/band_kernels.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>

namespace jelly {

namespace {

// Positions and velocities of the two ends of n consecutive springs of a band (a = slot,
// b = slot + offset), one array per coordinate.
struct BandEnds {
  const Real *xa, *ya, *za, *ua, *va, *wa;
  const Real *xb, *yb, *zb, *ub, *vb, *wb;
};

// A band's coefficients per slot: rest lengths always; ks and kd per slot, or (uniform) one
// ks and one kd for every slot whose rest length is > 0 (the springs; 0 in empty slots).
struct BandCoefficients {
  const Real* rest;
  const Real* ks;
  const Real* kd;
  Real uniform_ks, uniform_kd;
};

// Force on the first particle of each slot into fx, fy, fz. Returns the number of collapsed
// springs (shorter than kDegenerateLength l0; then the caller falls back). A template on
// uniform coefficients: a band of one ks and kd reads 8 bytes per slot instead of 24.
template <bool Uniform>
__attribute__((always_inline)) inline int band_forces_loop(int n, const BandEnds& e,
                                                           const BandCoefficients& c,
                                                           Real* __restrict fx, Real* __restrict fy,
                                                           Real* __restrict fz) {
  const Real* __restrict xa = e.xa;
  const Real* __restrict ya = e.ya;
  const Real* __restrict za = e.za;
  const Real* __restrict ua = e.ua;
  const Real* __restrict va = e.va;
  const Real* __restrict wa = e.wa;
  const Real* __restrict xb = e.xb;
  const Real* __restrict yb = e.yb;
  const Real* __restrict zb = e.zb;
  const Real* __restrict ub = e.ub;
  const Real* __restrict vb = e.vb;
  const Real* __restrict wb = e.wb;
  const Real* __restrict rest = c.rest;
  const Real* __restrict ks = c.ks;
  const Real* __restrict kd = c.kd;
  const Real uniform_ks = c.uniform_ks, uniform_kd = c.uniform_kd;
  int collapsed = 0;
  for (int j = 0; j < n; ++j) {
    // (Uniform: the same values as the per-slot arrays hold, 0 in empty slots.)
    const Real k_s = Uniform ? (rest[j] > 0 ? uniform_ks : 0.0) : ks[j];
    const Real k_d = Uniform ? (rest[j] > 0 ? uniform_kd : 0.0) : kd[j];
    const Real dx = xa[j] - xb[j], dy = ya[j] - yb[j], dz = za[j] - zb[j];
    const Real length = std::sqrt(dx * dx + dy * dy + dz * dz);
    // + tiny: a slot without a spring may join two coincident particles (its coefficients are 0).
    const Real inv = 1.0 / (length + 1e-300);
    const Real closing = ((ua[j] - ub[j]) * dx + (va[j] - vb[j]) * dy + (wa[j] - wb[j]) * dz) * inv;
    const Real magnitude = (-k_s * (length - rest[j]) - k_d * closing) * inv;
    fx[j] = magnitude * dx;
    fy[j] = magnitude * dy;
    fz[j] = magnitude * dz;
    collapsed += length < kDegenerateLength * rest[j];
  }
  return collapsed;
}

JELLY_VECTOR_CLONES
int band_forces(int n, const BandEnds& e, const BandCoefficients& c, Real* __restrict fx,
                Real* __restrict fy, Real* __restrict fz) {
  if (c.ks == nullptr) return band_forces_loop<true>(n, e, c, fx, fy, fz);
  return band_forces_loop<false>(n, e, c, fx, fy, fz);
}

// Springs per thread below which another thread costs more than it saves.
constexpr long kMinSpringsPerThread = 8192;

// A band is worth its empty slots when springs fill at least this fraction of them, and bands
// are worth their loop overhead when they hold this many springs on average.
constexpr Real kMinimumFill = 0.5;
constexpr int kMinimumSpringsPerBand = 4;

}  // namespace

namespace band_kernels {

JELLY_VECTOR_CLONES
void add(int n, const Real* __restrict tx, const Real* __restrict ty, const Real* __restrict tz,
         Real* __restrict ax, Real* __restrict ay, Real* __restrict az) {
  for (int j = 0; j < n; ++j) {
    ax[j] += tx[j];
    ay[j] += ty[j];
    az[j] += tz[j];
  }
}

JELLY_VECTOR_CLONES
void subtract(int n, const Real* __restrict tx, const Real* __restrict ty,
              const Real* __restrict tz, Real* __restrict ax, Real* __restrict ay,
              Real* __restrict az) {
  for (int j = 0; j < n; ++j) {
    ax[j] -= tx[j];
    ay[j] -= ty[j];
    az[j] -= tz[j];
  }
}

JELLY_VECTOR_CLONES
void add_difference(int n, const Real* __restrict ux, const Real* __restrict uy,
                    const Real* __restrict uz, const Real* __restrict wx, const Real* __restrict wy,
                    const Real* __restrict wz, Real* __restrict ax, Real* __restrict ay,
                    Real* __restrict az) {
  for (int j = 0; j < n; ++j) {
    ax[j] += ux[j] - wx[j];
    ay[j] += uy[j] - wy[j];
    az[j] += uz[j] - wz[j];
  }
}

JELLY_VECTOR_CLONES
void add_then_subtract(int n, const Real* __restrict ux, const Real* __restrict uy,
                       const Real* __restrict uz, const Real* __restrict wx,
                       const Real* __restrict wy, const Real* __restrict wz, Real* __restrict ax,
                       Real* __restrict ay, Real* __restrict az) {
  for (int j = 0; j < n; ++j) {
    ax[j] = (ax[j] + ux[j]) - wx[j];
    ay[j] = (ay[j] + uy[j]) - wy[j];
    az[j] = (az[j] + uz[j]) - wz[j];
  }
}

namespace {

// The ranges of add_ends and add_then_subtract_ends: `both` for the particles in both ranges,
// add or subtract alone elsewhere.
template <class Both>
void ends(int a, int b, int a0, int a1, int b0, int b1, const Real* tx, const Real* ty,
          const Real* tz, Real* ax, Real* ay, Real* az, Both both) {
  const int o0 = std::max(a0, b0), o1 = std::min(a1, b1);
  const auto first_ends = [&](int i0, int i1) {
    if (i0 < i1)
      add(i1 - i0, tx + (i0 - a), ty + (i0 - a), tz + (i0 - a), ax + i0, ay + i0, az + i0);
  };
  const auto second_ends = [&](int i0, int i1) {
    if (i0 < i1)
      subtract(i1 - i0, tx + (i0 - b), ty + (i0 - b), tz + (i0 - b), ax + i0, ay + i0, az + i0);
  };
  if (o0 >= o1) {
    first_ends(a0, a1);
    second_ends(b0, b1);
    return;
  }
  both(o1 - o0, tx + (o0 - a), ty + (o0 - a), tz + (o0 - a), tx + (o0 - b), ty + (o0 - b),
       tz + (o0 - b), ax + o0, ay + o0, az + o0);
  first_ends(a0, o0);
  first_ends(o1, a1);
  second_ends(b0, o0);
  second_ends(o1, b1);
}

}  // namespace

void add_ends(int a, int b, int a0, int a1, int b0, int b1, const Real* tx, const Real* ty,
              const Real* tz, Real* ax, Real* ay, Real* az) {
  // Elsewhere than in both ranges +t or -t alone, which are the same bits as the difference
  // with a zero term (x - 0 = x, acc + -x = acc - x).
  ends(a, b, a0, a1, b0, b1, tx, ty, tz, ax, ay, az, add_difference);
}

void add_then_subtract_ends(int a, int b, int a0, int a1, int b0, int b1, const Real* tx,
                            const Real* ty, const Real* tz, Real* ax, Real* ay, Real* az) {
  ends(a, b, a0, a1, b0, b1, tx, ty, tz, ax, ay, az, add_then_subtract);
}

}  // namespace band_kernels

SpringBands::Band::Reach SpringBands::Band::reach(int p0, int p1) const {
  Reach r;
  r.lo = std::max(0, p0 - offset - first);
  r.hi = std::min(slots(), p1 - first);
  r.a0 = std::max(p0, first + r.lo);
  r.a1 = std::min(p1, first + r.hi);
  r.b0 = std::max(p0, first + offset + r.lo);
  r.b1 = std::min(p1, first + offset + r.hi);
  return r;
}

SpringBands::SpringBands(const Model& model)
    : particles_(model.num_particles()), springs_(model.springs.size()) {
  const Springs& s = model.springs;
  std::map<int, std::vector<int>> by_offset;  // offset -> springs
  for (int k = 0; k < s.size(); ++k) by_offset[std::abs(s.b[k] - s.a[k])].push_back(k);
  dense_ = springs_ > 0 && by_offset.count(0) == 0 &&
           springs_ >= kMinimumSpringsPerBand * static_cast<int>(by_offset.size());
  for (const auto& [offset, springs] : by_offset) {
    if (!dense_) break;
    int lo = particles_, hi = -1;
    for (int k : springs) {
      lo = std::min(lo, std::min(s.a[k], s.b[k]));
      hi = std::max(hi, std::min(s.a[k], s.b[k]));
    }
    Band band;
    band.offset = offset;
    band.first = lo;
    const int slots = hi - lo + 1;
    if (static_cast<Real>(springs.size()) < kMinimumFill * slots) dense_ = false;
    band.spring.assign(slots, -1);
    for (int k : springs) {
      int& slot = band.spring[std::min(s.a[k], s.b[k]) - lo];
      if (slot >= 0) dense_ = false;  // two springs on one pair
      slot = k;
    }
    max_offset_ = std::max(max_offset_, offset);
    bands_.push_back(std::move(band));
  }
  if (!dense_) {
    bands_.clear();
    return;
  }
  copy_coefficients(model);
}

bool SpringBands::fits(const Model& model) const {
  return model.num_particles() == particles_ && model.springs.size() == springs_;
}

void SpringBands::copy_coefficients(const Model& model) {
  const Springs& s = model.springs;
  for (Band& band : bands_) {
    const size_t slots = band.spring.size();
    band.rest.assign(slots, 0.0);
    band.ks.assign(slots, 0.0);
    band.kd.assign(slots, 0.0);
    bool seen = false;
    band.uniform = true;
    for (size_t j = 0; j < slots; ++j) {
      const int k = band.spring[j];
      if (k < 0) continue;
      band.rest[j] = s.rest_length[k];
      band.ks[j] = s.ks[k];
      band.kd[j] = s.kd[k];
      if (!seen) band.uniform_ks = s.ks[k], band.uniform_kd = s.kd[k], seen = true;
      // (Bit patterns: +0 and -0 are not the same coefficient.)
      band.uniform = band.uniform && s.rest_length[k] > 0 &&
                     std::memcmp(&s.ks[k], &band.uniform_ks, sizeof(Real)) == 0 &&
                     std::memcmp(&s.kd[k], &band.uniform_kd, sizeof(Real)) == 0;
    }
  }
}

void SpringBands::compute_forces(const Model& model, const VecX& x, const VecX& v, VecX& f,
                                 int threads) const {
  evaluate(model, x, v, f, threads, false, nullptr);
}

void SpringBands::compute_accelerations(const Model& model, const VecX& x, const VecX& v, VecX& a,
                                        int threads, const RangeTerms* terms) const {
  evaluate(model, x, v, a, threads, true, terms);
}

void SpringBands::evaluate(const Model& model, const VecX& x, const VecX& v, VecX& f, int threads,
                           bool accelerations, const RangeTerms* terms) const {
  // Without the bands, or after a collapsed spring: the serial loop, the terms, the division.
  const auto serial = [&] {
    ::jelly::compute_forces(model, x, v, f);
    if (terms != nullptr) terms->add(0, model.num_particles(), f);
    if (accelerations) divide_by_masses(model, f, threads);
  };
  if (!dense_ || !fits(model)) {
    serial();
    return;
  }
  const int n = particles_;
  const int team = parallel::team_size(threads, springs_, kMinSpringsPerThread);
  if (static_cast<int>(workspaces_.size()) != team) workspaces_.assign(team, {});
  int parts_used = 1;
  const Real* m = model.mass.data();
  const Vec3 g = model.gravity;
  // Each thread copies the positions and velocities of every particle its slots reach (its own
  // and max_offset on either side) into its own arrays: no thread waits for another.
  // The particles split between the threads as fast as each got through its part last time
  // (parallel::BalancedSplit: each particle's forces are the same bits whichever thread sums them).
  parallel::run(team, [&](int part, int parts) {
    const auto start = std::chrono::steady_clock::now();
    const parallel::Range range = split_.range(n, part, parts);
    const int p0 = static_cast<int>(range.begin), p1 = static_cast<int>(range.end);
    const int e0 = std::max(0, p0 - max_offset_), e1 = std::min(n, p1 + max_offset_);
    const int reach = e1 - e0, own = p1 - p0;
    if (part == 0) parts_used = parts;
    Workspace& w = workspaces_[part];
    // x, y, z, u, v, w of the particles within reach; the band forces of the slots touching its
    // own particles (at most own + max_offset); the sums of its own particles. Sized on the first
    // call with this team for the largest part the split gives (and again if OpenMP gives fewer
    // threads than asked: larger ranges).
    const size_t largest = std::min<size_t>(n, parallel::BalancedSplit::largest(n, parts));
    const size_t size = 6 * std::min<size_t>(n, largest + 2 * max_offset_) +
                        3 * (largest + max_offset_) + 3 * largest;
    if (w.data.size() < size) w.data.assign(size, 0.0);
    Real* px = w.data.data();
    Real* py = px + reach;
    Real* pz = py + reach;
    Real* pu = pz + reach;
    Real* pv = pu + reach;
    Real* pw = pv + reach;
    Real* fx = pw + reach;
    Real* fy = fx + (own + max_offset_);
    Real* fz = fy + (own + max_offset_);
    Real* ax = fz + (own + max_offset_);
    Real* ay = ax + own;
    Real* az = ay + own;
    const Real* xs = x.data();
    const Real* vs = v.data();
    for (int i = e0; i < e1; ++i) {
      const int k = i - e0;
      px[k] = xs[3 * i];
      py[k] = xs[3 * i + 1];
      pz[k] = xs[3 * i + 2];
      pu[k] = vs[3 * i];
      pv[k] = vs[3 * i + 1];
      pw[k] = vs[3 * i + 2];
    }
    for (int i = p0; i < p1; ++i) {
      ax[i - p0] = m[i] * g.x();
      ay[i - p0] = m[i] * g.y();
      az[i - p0] = m[i] * g.z();
    }
    int collapsed = 0;
    for (const Band& band : bands_) {
      const Band::Reach r = band.reach(p0, p1);
      if (r.lo >= r.hi) continue;
      const int a = band.first + r.lo - e0, b = a + band.offset;
      const BandEnds ends{px + a, py + a, pz + a, pu + a, pv + a, pw + a,
                          px + b, py + b, pz + b, pu + b, pv + b, pw + b};
      const BandCoefficients coefficients{
          band.rest.data() + r.lo, band.uniform ? nullptr : band.ks.data() + r.lo,
          band.uniform ? nullptr : band.kd.data() + r.lo, band.uniform_ks, band.uniform_kd};
      collapsed += band_forces(r.hi - r.lo, ends, coefficients, fx, fy, fz);
      // As the serial loop: + on particle a of every slot, then - on particle b (one pass).
      // Indices relative to p0: slot lo's first end is band.first + lo.
      const int a_rel = band.first + r.lo - p0;
      band_kernels::add_then_subtract_ends(a_rel, a_rel + band.offset, r.a0 - p0, r.a1 - p0,
                                           r.b0 - p0, r.b1 - p0, fx, fy, fz, ax, ay, az);
    }
    w.collapsed = collapsed;
    // Written even when a spring collapsed somewhere: the fallback below then overwrites f.
    Real* pf = f.data();
    if (accelerations && terms != nullptr) {  // the sums, the terms, then the division
      for (int i = p0; i < p1; ++i) {
        pf[3 * i] = ax[i - p0];
        pf[3 * i + 1] = ay[i - p0];
        pf[3 * i + 2] = az[i - p0];
      }
      terms->add(p0, p1, f);
      for (int i = p0; i < p1; ++i) {
        const Real inv = 1.0 / m[i];
        pf[3 * i] *= inv;
        pf[3 * i + 1] *= inv;
        pf[3 * i + 2] *= inv;
      }
    } else if (accelerations) {  // as divide_by_masses, on the sums still in this thread's cache
      for (int i = p0; i < p1; ++i) {
        const Real inv = 1.0 / m[i];
        pf[3 * i] = ax[i - p0] * inv;
        pf[3 * i + 1] = ay[i - p0] * inv;
        pf[3 * i + 2] = az[i - p0] * inv;
      }
    } else {
      for (int i = p0; i < p1; ++i) {
        pf[3 * i] = ax[i - p0];
        pf[3 * i + 1] = ay[i - p0];
        pf[3 * i + 2] = az[i - p0];
      }
    }
    split_.record(part,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  });
  split_.update(parts_used);
  for (int part = 0; part < parts_used; ++part) {
    if (workspaces_[part].collapsed > 0) {
      serial();  // a collapsed spring: compute_forces gives it its rest direction
      return;
    }
  }
}

}  // namespace jelly
