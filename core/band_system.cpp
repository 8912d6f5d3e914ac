#include <jelly/core/detail/band_system.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <jelly/core/detail/band_kernels.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>

namespace jelly {

namespace {

// Springs per thread below which another thread costs more than it saves (as the force loop).
constexpr long kMinSlotsPerThread = 8192;
// Per-thread buffers of a pass over a band's slots: c1, c2, e1, ux, uy, uz, tx, ty, tz.
constexpr size_t kBuffers = 9;

// Rows per block of assemble() and multiply() for bands reaching `max_offset` particles: a block
// reads the inputs of its rows and of the max_offset particles on either side (positions and input,
// 48 bytes a particle) and computes the terms of block + offset slots per band, so blocks much
// longer than the largest offset waste no work, and short enough that what a block touches stays in
// a core's L2 cache (docs/implicit.md, "Matrix-free CG on lattices").
int row_block_for(int max_offset) { return std::max(8192, 2 * max_offset); }

struct Ends {
  const Real *xa, *ya, *za, *xb, *yb, *zb;
};

// max(x, 0) as std::max computes it (x itself unless x < 0; NaN stays NaN), by value.
inline Real positive_part(Real x) { return x < 0 ? 0.0 : x; }

// The loop of band_blocks for one definiteness fix (1 kClampCompressed, 2 kProjectPsd, else
// none): a template, because a select on the fix in the loop kept it from being vectorised.
template <int Fix>
__attribute__((always_inline)) inline int band_blocks_loop(
    int n, Real alpha, Real beta, Ends x, Ends v, Ends w, const Real* __restrict rest,
    const Real* __restrict ks, const Real* __restrict kd, Real* __restrict c1, Real* __restrict c2,
    Real* __restrict e1, Real* __restrict ux, Real* __restrict uy, Real* __restrict uz,
    Real* __restrict tx, Real* __restrict ty, Real* __restrict tz) {
  const Real* __restrict xa = x.xa;
  const Real* __restrict ya = x.ya;
  const Real* __restrict za = x.za;
  const Real* __restrict xb = x.xb;
  const Real* __restrict yb = x.yb;
  const Real* __restrict zb = x.zb;
  const Real* __restrict va = v.xa;
  const Real* __restrict vb = v.xb;
  const Real* __restrict va1 = v.ya;
  const Real* __restrict vb1 = v.yb;
  const Real* __restrict va2 = v.za;
  const Real* __restrict vb2 = v.zb;
  const Real* __restrict wa = w.xa;
  const Real* __restrict wb = w.xb;
  const Real* __restrict wa1 = w.ya;
  const Real* __restrict wb1 = w.yb;
  const Real* __restrict wa2 = w.za;
  const Real* __restrict wb2 = w.zb;
  int collapsed = 0;
  for (int j = 0; j < n; ++j) {
    const Real dx = xa[j] - xb[j], dy = ya[j] - yb[j], dz = za[j] - zb[j];
    const Real length = std::sqrt(dx * dx + dy * dy + dz * dz);
    // + tiny: a slot without a spring may join two coincident particles (its coefficients are 0).
    const Real inv = 1.0 / (length + 1e-300);
    const Real u0 = dx * inv, u1 = dy * inv, u2 = dz * inv;
    const Real c = (va[j] - vb[j]) * u0 + (va1[j] - vb1[j]) * u1 + (va2[j] - vb2[j]) * u2;
    const Real spring_geometric = ks[j] * (1 - rest[j] * inv);
    const Real damper_geometric = kd[j] * c * inv;
    Real s;
    if constexpr (Fix == 1) {
      s = positive_part(spring_geometric) + positive_part(damper_geometric);
    } else if constexpr (Fix == 2) {
      s = positive_part(spring_geometric + damper_geometric);
    } else {
      s = spring_geometric + damper_geometric;
    }
    const Real along = ks[j] - s;
    c1[j] = alpha * kd[j] + beta * along;
    c2[j] = beta * s;
    e1[j] = c1[j] * inv * inv;  // 0 for an empty slot (0 * 1e300 * 1e300 = 0)
    ux[j] = u0;
    uy[j] = u1;
    uz[j] = u2;
    const Real d0 = wa[j] - wb[j], d1 = wa1[j] - wb1[j], d2 = wa2[j] - wb2[j];
    const Real ud = along * (u0 * d0 + u1 * d1 + u2 * d2);
    tx[j] = -ud * u0 - s * d0;
    ty[j] = -ud * u1 - s * d1;
    tz[j] = -ud * u2 - s * d2;
    collapsed += length < kDegenerateLength * rest[j];
  }
  return collapsed;
}

// Per slot: B = c1 u u^T + c2 I and t = K_k (w_a - w_b), with (the spring_blocks of
// core/jacobian.cpp) s the geometric stiffness after the definiteness fix,
// K_k = -(ks - s) u u^T - s I, D_k = -kd u u^T, B = -alpha D_k - beta K_k. Returns the number of
// collapsed springs.
JELLY_VECTOR_CLONES
int band_blocks(int n, int fix, Real alpha, Real beta, Ends x, Ends v, Ends w,
                const Real* __restrict rest, const Real* __restrict ks, const Real* __restrict kd,
                Real* __restrict c1, Real* __restrict c2, Real* __restrict e1, Real* __restrict ux,
                Real* __restrict uy, Real* __restrict uz, Real* __restrict tx, Real* __restrict ty,
                Real* __restrict tz) {
  if (fix == 1)
    return band_blocks_loop<1>(n, alpha, beta, x, v, w, rest, ks, kd, c1, c2, e1, ux, uy, uz, tx,
                               ty, tz);
  if (fix == 2)
    return band_blocks_loop<2>(n, alpha, beta, x, v, w, rest, ks, kd, c1, c2, e1, ux, uy, uz, tx,
                               ty, tz);
  return band_blocks_loop<0>(n, alpha, beta, x, v, w, rest, ks, kd, c1, c2, e1, ux, uy, uz, tx, ty,
                             tz);
}

// Per slot t = B (p_a - p_b) = c1 (u . d) u + c2 d = e1 (e . d) e + c2 d, with e = x_a - x_b
// (u = e / |e|) recomputed from the positions and e1 = c1 / |e|^2: 16 bytes per slot to read
// instead of 40 (the product is bound by memory traffic at n = 40; docs/implicit.md), 8 with
// the coefficients in single precision (C = float).
template <class C>
__attribute__((always_inline)) inline void band_products_loop(
    int n, Ends x, Ends p, const C* __restrict e1, const C* __restrict c2, Real* __restrict tx,
    Real* __restrict ty, Real* __restrict tz) {
  const Real* __restrict xa = x.xa;
  const Real* __restrict ya = x.ya;
  const Real* __restrict za = x.za;
  const Real* __restrict xb = x.xb;
  const Real* __restrict yb = x.yb;
  const Real* __restrict zb = x.zb;
  const Real* __restrict pxa = p.xa;
  const Real* __restrict pya = p.ya;
  const Real* __restrict pza = p.za;
  const Real* __restrict pxb = p.xb;
  const Real* __restrict pyb = p.yb;
  const Real* __restrict pzb = p.zb;
  for (int j = 0; j < n; ++j) {
    const Real u0 = xa[j] - xb[j], u1 = ya[j] - yb[j], u2 = za[j] - zb[j];
    const Real d0 = pxa[j] - pxb[j], d1 = pya[j] - pyb[j], d2 = pza[j] - pzb[j];
    const Real c = static_cast<Real>(c2[j]);
    const Real ud = static_cast<Real>(e1[j]) * (u0 * d0 + u1 * d1 + u2 * d2);
    tx[j] = ud * u0 + c * d0;
    ty[j] = ud * u1 + c * d1;
    tz[j] = ud * u2 + c * d2;
  }
}

JELLY_VECTOR_CLONES
void band_products(int n, Ends x, Ends p, const Real* __restrict e1, const Real* __restrict c2,
                   Real* __restrict tx, Real* __restrict ty, Real* __restrict tz) {
  band_products_loop<Real>(n, x, p, e1, c2, tx, ty, tz);
}

JELLY_VECTOR_CLONES
void band_products_single(int n, Ends x, Ends p, const float* __restrict e1,
                          const float* __restrict c2, Real* __restrict tx, Real* __restrict ty,
                          Real* __restrict tz) {
  band_products_loop<float>(n, x, p, e1, c2, tx, ty, tz);
}

// The six entries xx, yy, zz, xy, xz, yz of B = c1 u u^T + c2 I added to d[0..5][j].
JELLY_VECTOR_CLONES
void accumulate_blocks(int n, const Real* __restrict c1, const Real* __restrict c2,
                       const Real* __restrict ux, const Real* __restrict uy,
                       const Real* __restrict uz, Real* __restrict dxx, Real* __restrict dyy,
                       Real* __restrict dzz, Real* __restrict dxy, Real* __restrict dxz,
                       Real* __restrict dyz) {
  for (int j = 0; j < n; ++j) {
    dxx[j] += c1[j] * ux[j] * ux[j] + c2[j];
    dyy[j] += c1[j] * uy[j] * uy[j] + c2[j];
    dzz[j] += c1[j] * uz[j] * uz[j] + c2[j];
    dxy[j] += c1[j] * ux[j] * uy[j];
    dxz[j] += c1[j] * ux[j] * uz[j];
    dyz[j] += c1[j] * uy[j] * uz[j];
  }
}

// The terms of `len` slots from position q of a thread's per-slot buffers, at the particles
// from `particle` on (the slots' first ends, or their second ends when !first_end): +t (first
// ends) or -t (second ends) into the accumulators acc (x, y, z: 3 arrays of n) and each slot's
// block B into the particles' diagonal blocks diag (xx, yy, zz, xy, xz, yz: 6 arrays of n).
void add_slot_terms(int n, int particle, int len, int q, bool first_end, const Real* c1,
                    const Real* c2, const Real* ux, const Real* uy, const Real* uz, const Real* tx,
                    const Real* ty, const Real* tz, Real* acc, Real* diag) {
  Real* ax = acc + particle;
  if (first_end) {
    band_kernels::add(len, tx + q, ty + q, tz + q, ax, ax + n, ax + 2 * n);
  } else {
    band_kernels::subtract(len, tx + q, ty + q, tz + q, ax, ax + n, ax + 2 * n);
  }
  Real* d = diag + particle;
  accumulate_blocks(len, c1 + q, c2 + q, ux + q, uy + q, uz + q, d, d + n, d + 2 * n, d + 3 * n,
                    d + 4 * n, d + 5 * n);
}

}  // namespace

BandSystem::BandSystem(const SpringBands& bands, int num_particles, bool single_precision)
    : bands_(&bands), num_particles_(num_particles), single_(single_precision) {
  for (const SpringBands::Band& band : bands.bands()) {
    Slots s;
    const size_t n = band.spring.size();
    if (single_) {
      s.e1_single.assign(n, 0.0F);
      s.c2_single.assign(n, 0.0F);
    } else {
      s.e1.assign(n, 0.0);
      s.c2.assign(n, 0.0);
    }
    slots_.push_back(std::move(s));
  }
  for (const auto& band : bands.bands()) slots_total_ += band.slots();
  stride_ = static_cast<size_t>(num_particles) + static_cast<size_t>(bands.max_offset());
  block_ = std::max(1, row_block_for(bands.max_offset()));
  mass_.assign(num_particles, 0.0);
  diagonal_.assign(6 * static_cast<size_t>(num_particles), 0.0);
  positions_.assign(3 * static_cast<size_t>(num_particles), 0.0);
  scratch_.assign(9 * static_cast<size_t>(num_particles), 0.0);
}

int BandSystem::team(int threads) const {
  const int team = parallel::team_size(threads, slots_total_, kMinSlotsPerThread);
  if (band_.size() < static_cast<size_t>(team) * kBuffers * stride_) {
    band_.assign(static_cast<size_t>(team) * kBuffers * stride_, 0.0);
  }
  return team;
}

bool BandSystem::assemble(const Model& model, const VecX& x, const VecX& v, DefinitenessFix fix,
                          Real alpha, Real beta, const VecX& w, VecX& kw, int threads) {
  const int n = num_particles_;
  extra_column_.clear();
  extra_value_.clear();
  const std::vector<SpringBands::Band>& bands = bands_->bands();
  const int team = this->team(threads);
  const size_t stride = stride_;
  if (collapsed_.size() < static_cast<size_t>(team)) collapsed_.assign(team, 0);
  const int fix_code = fix == DefinitenessFix::kClampCompressed ? 1
                       : fix == DefinitenessFix::kProjectPsd    ? 2
                                                                : 0;
  Real* sx = positions_.data();
  Real* sv = scratch_.data();
  Real* sw = sv + 3 * static_cast<size_t>(n);
  Real* acc = sw + 3 * static_cast<size_t>(n);
  Real* diag = diagonal_.data();
  const Real* m = model.mass.data();
  bool any_collapsed = false;
  parallel::run(team, [&](int part, int parts) {
    const parallel::Range range = parallel::split(n, part, parts);
    const int p0 = static_cast<int>(range.begin), p1 = static_cast<int>(range.end);
    for (int i = p0; i < p1; ++i) {
      for (int c = 0; c < 3; ++c) {
        sx[c * n + i] = x[3 * i + c];
        sv[c * n + i] = v[3 * i + c];
        sw[c * n + i] = w[3 * i + c];
        acc[c * n + i] = 0;
      }
      for (int c = 0; c < 6; ++c) diag[c * static_cast<size_t>(n) + i] = 0;
      mass_[i] = m[i];
    }
#pragma omp barrier
    Real* buffer = band_.data() + static_cast<size_t>(part) * kBuffers * stride;
    Real* c1 = buffer;
    Real* c2 = c1 + stride;
    Real* e1 = c2 + stride;
    Real* ux = e1 + stride;
    Real* uy = ux + stride;
    Real* uz = uy + stride;
    Real* tx = uz + stride;
    Real* ty = tx + stride;
    Real* tz = ty + stride;
    int collapsed = 0;
    // Block by block as multiply() (every band for one block of rows, then the next; a block's
    // rows the same bits as a thread's range would give them).
    for (int q0 = p0; q0 < p1; q0 += block_) {
      const int q1 = std::min(p1, q0 + block_);
      for (size_t k = 0; k < bands.size(); ++k) {
        const SpringBands::Band& band = bands[k];
        const SpringBands::Band::Reach r = band.reach(q0, q1);
        if (r.lo >= r.hi) continue;
        const int a = band.first + r.lo, b = a + band.offset;
        const Ends ex{sx + a, sx + n + a, sx + 2 * n + a, sx + b, sx + n + b, sx + 2 * n + b};
        const Ends ev{sv + a, sv + n + a, sv + 2 * n + a, sv + b, sv + n + b, sv + 2 * n + b};
        const Ends ew{sw + a, sw + n + a, sw + 2 * n + a, sw + b, sw + n + b, sw + 2 * n + b};
        const int found = band_blocks(r.hi - r.lo, fix_code, alpha, beta, ex, ev, ew,
                                      band.rest.data() + r.lo, band.ks.data() + r.lo,
                                      band.kd.data() + r.lo, c1, c2, e1, ux, uy, uz, tx, ty, tz);
        // This block stores the slots whose first particle is its own.
        Slots& out = slots_[k];
        if (r.a0 < r.a1) {
          const int q = r.a0 - a, slot = r.a0 - band.first, len = r.a1 - r.a0;
          if (single_) {  // rounded to the nearest float
            std::copy(e1 + q, e1 + q + len, out.e1_single.data() + slot);
            std::copy(c2 + q, c2 + q + len, out.c2_single.data() + slot);
          } else {
            std::copy(e1 + q, e1 + q + len, out.e1.data() + slot);
            std::copy(c2 + q, c2 + q + len, out.c2.data() + slot);
          }
          add_slot_terms(n, r.a0, len, q, true, c1, c2, ux, uy, uz, tx, ty, tz, acc, diag);
        }
        collapsed += found;
        if (r.b0 < r.b1) {
          add_slot_terms(n, r.b0, r.b1 - r.b0, r.b0 - b, false, c1, c2, ux, uy, uz, tx, ty, tz, acc,
                         diag);
        }
      }
    }
    collapsed_[part] = collapsed;
    for (int i = p0; i < p1; ++i) {
      for (int c = 0; c < 3; ++c) kw[3 * i + c] = acc[c * n + i];
    }
#pragma omp barrier
#pragma omp single
    for (int t = 0; t < parts; ++t) any_collapsed = any_collapsed || collapsed_[t] > 0;
  });
  return !any_collapsed;
}

void BandSystem::add_diagonal(int particle, Real value) { mass_[particle] += value; }

void BandSystem::diagonal_block(int i, Real out[9]) const {
  const size_t n = static_cast<size_t>(num_particles_);
  const Real* d = diagonal_.data() + i;
  const Real m = mass_[i];
  out[0] = d[0] + m;
  out[4] = d[n] + m;
  out[8] = d[2 * n] + m;
  out[1] = out[3] = d[3 * n];
  out[2] = out[6] = d[4 * n];
  out[5] = out[7] = d[5 * n];
  if (extra_column_.empty()) return;
  for (int e = extra_start_[i]; e < extra_start_[i + 1]; ++e) {
    if (extra_column_[e] != i) continue;
    const Real* b = extra_value_.data() + 9 * static_cast<size_t>(e);
    for (int k = 0; k < 9; ++k) out[k] += b[k];
  }
}

void BandSystem::set_extra_blocks(const ForceJacobian& jacobian, Real alpha, Real beta) {
  const int n = num_particles_;
  extra_column_.clear();
  extra_value_.clear();
  if (jacobian.empty()) return;
  // Counting sort of the 2 entries per block by row.
  extra_start_.assign(static_cast<size_t>(n) + 1, 0);
  for (const ForceJacobian::Block& b : jacobian.blocks()) {
    ++extra_start_[b.i + 1];
    ++extra_start_[b.j + 1];
  }
  for (int i = 0; i < n; ++i) extra_start_[i + 1] += extra_start_[i];
  const size_t entries = static_cast<size_t>(extra_start_[n]);
  extra_column_.resize(entries);
  extra_value_.resize(9 * entries);
  extra_fill_.assign(extra_start_.begin(), extra_start_.end() - 1);
  const auto put = [&](int row, int column, const Eigen::Matrix3d& value) {
    const int e = extra_fill_[row]++;
    extra_column_[e] = column;
    Real* out = extra_value_.data() + 9 * static_cast<size_t>(e);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out[3 * r + c] = value(r, c);
  };
  for (const ForceJacobian::Block& b : jacobian.blocks()) {
    const Eigen::Matrix3d half = -0.5 * (alpha * b.dfdv + beta * b.dfdx);
    put(b.i, b.j, half);
    put(b.j, b.i, half.transpose());
  }
}

void BandSystem::slot_block(size_t band, int slot, Real out[6]) const {
  const int n = num_particles_;
  const SpringBands::Band& b = bands_->bands()[band];
  const int i = b.first + slot, j = i + b.offset;
  const Real* sx = positions_.data();
  const Real e[3] = {sx[i] - sx[j], sx[n + i] - sx[n + j], sx[2 * n + i] - sx[2 * n + j]};
  const Slots& s = slots_[band];
  const Real e1 = single_ ? s.e1_single[slot] : s.e1[slot];
  const Real c2 = single_ ? s.c2_single[slot] : s.c2[slot];
  out[0] = e1 * e[0] * e[0] + c2;
  out[1] = e1 * e[1] * e[1] + c2;
  out[2] = e1 * e[2] * e[2] + c2;
  out[3] = e1 * e[0] * e[1];
  out[4] = e1 * e[0] * e[2];
  out[5] = e1 * e[1] * e[2];
}

void BandSystem::multiply_rows(const VecX& p, const std::vector<int>& particles, VecX& y,
                               int threads) const {
  const int n = num_particles_;
  const Real* sx = positions_.data();
  const std::vector<SpringBands::Band>& bands = bands_->bands();
  // The term t of `slot` of band k, as band_products computes it.
  const auto term = [&](size_t k, int slot, Real t[3]) {
    const SpringBands::Band& band = bands[k];
    const int a = band.first + slot, b = a + band.offset;
    const Real u0 = sx[a] - sx[b], u1 = sx[n + a] - sx[n + b], u2 = sx[2 * n + a] - sx[2 * n + b];
    const Real d0 = p[3 * a] - p[3 * b], d1 = p[3 * a + 1] - p[3 * b + 1],
               d2 = p[3 * a + 2] - p[3 * b + 2];
    const Slots& coefficients = slots_[k];
    const Real e1 = single_ ? coefficients.e1_single[slot] : coefficients.e1[slot];
    const Real c2 = single_ ? coefficients.c2_single[slot] : coefficients.c2[slot];
    const Real ud = e1 * (u0 * d0 + u1 * d1 + u2 * d2);
    t[0] = ud * u0 + c2 * d0;
    t[1] = ud * u1 + c2 * d1;
    t[2] = ud * u2 + c2 * d2;
  };
  const auto row = [&](int i) {
    Real acc[3];
    for (int c = 0; c < 3; ++c) acc[c] = mass_[i] * p[3 * i + c];
    // Band by band as multiply adds them (band_kernels::add_ends): t_first - t_second where the
    // particle is both ends' of a slot, else +t_first or -t_second.
    for (size_t k = 0; k < bands.size(); ++k) {
      const SpringBands::Band& band = bands[k];
      const int first = i - band.first, second = first - band.offset;
      const bool is_first = first >= 0 && first < band.slots();
      const bool is_second = second >= 0 && second < band.slots();
      Real tf[3] = {}, ts[3] = {};
      if (is_first) term(k, first, tf);
      if (is_second) term(k, second, ts);
      for (int c = 0; c < 3; ++c) {
        if (is_first && is_second) {
          acc[c] += tf[c] - ts[c];
        } else if (is_first) {
          acc[c] += tf[c];
        } else if (is_second) {
          acc[c] -= ts[c];
        }
      }
    }
    for (int e = extra_column_.empty() ? 0 : extra_start_[i];
         !extra_column_.empty() && e < extra_start_[i + 1]; ++e) {
      const Real* b = extra_value_.data() + 9 * static_cast<size_t>(e);
      const int j = extra_column_[e];
      for (int c = 0; c < 3; ++c)
        acc[c] += b[3 * c] * p[3 * j] + b[3 * c + 1] * p[3 * j + 1] + b[3 * c + 2] * p[3 * j + 2];
    }
    for (int c = 0; c < 3; ++c) y[3 * i + c] = acc[c];
  };
  // A row costs a few hundred operations: a thread for fewer rows would not pay its start.
  constexpr long kMinRowsPerThread = 128;
  parallel::for_ranges(
      threads, static_cast<long>(particles.size()),
      [&](long begin, long end) {
        for (long r = begin; r < end; ++r) row(particles[r]);
      },
      kMinRowsPerThread);
}

void BandSystem::multiply(const VecX& p, VecX& y, int threads, ProductFilter filter) const {
  const int n = num_particles_;
  const std::vector<SpringBands::Band>& bands = bands_->bands();
  const int team = this->team(threads);
  const size_t stride = stride_;
  const int block = block_;
  const Real* sx = positions_.data();
  Real* sp = scratch_.data();
  Real* acc = sp + 3 * static_cast<size_t>(n);
  int parts_used = 1;
  // The particles split between the threads as fast as each got through its part last time
  // (parallel::BalancedSplit: a particle's row is the same bits whichever thread computes it).
  using Clock = std::chrono::steady_clock;
  parallel::run(team, [&](int part, int parts) {
    auto start = Clock::now();
    const parallel::Range range = split_.range(n, part, parts);
    const int p0 = static_cast<int>(range.begin), p1 = static_cast<int>(range.end);
    for (int i = p0; i < p1; ++i) {
      Real q[3] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
      if (filter.slot != nullptr && filter.slot[i] >= 0) {
        const Real* f = filter.map + 9 * static_cast<size_t>(filter.slot[i]);
        const Real q0 = q[0], q1 = q[1], q2 = q[2];
        // Summed as Eigen's 3x3 product does (a0 + (a1 + a2)): the same bits as S_c p_c.
        for (int c = 0; c < 3; ++c) q[c] = f[c] * q0 + (f[3 + c] * q1 + f[6 + c] * q2);
      }
      for (int c = 0; c < 3; ++c) sp[c * n + i] = q[c];
    }
    double seconds = std::chrono::duration<double>(Clock::now() - start).count();
#pragma omp barrier
    start = Clock::now();
    Real* tx = band_.data() + static_cast<size_t>(part) * kBuffers * stride;
    Real* ty = tx + stride;
    Real* tz = ty + stride;
    // The thread's rows block by block (block_ particles), every band for one block before the
    // next: a block's rows, and the inputs within the bands' reach of it, stay in the cache
    // through its bands (each band a pass over the whole range read them from memory once per
    // band at n = 40). A block is computed as a thread's range would be (the slots at its
    // boundaries by both blocks), so each row is the same bits for any block size.
    for (int q0 = p0; q0 < p1; q0 += block) {
      const int q1 = std::min(p1, q0 + block);
      for (int i = q0; i < q1; ++i) {
        for (int c = 0; c < 3; ++c) acc[c * n + i] = mass_[i] * sp[c * n + i];
      }
      for (size_t k = 0; k < bands.size(); ++k) {
        const SpringBands::Band& band = bands[k];
        const SpringBands::Band::Reach r = band.reach(q0, q1);
        if (r.lo >= r.hi) continue;
        const int a = band.first + r.lo, b = a + band.offset;
        const Ends ex{sx + a, sx + n + a, sx + 2 * n + a, sx + b, sx + n + b, sx + 2 * n + b};
        const Ends ep{sp + a, sp + n + a, sp + 2 * n + a, sp + b, sp + n + b, sp + 2 * n + b};
        const Slots& s = slots_[k];
        if (single_) {
          band_products_single(r.hi - r.lo, ex, ep, s.e1_single.data() + r.lo,
                               s.c2_single.data() + r.lo, tx, ty, tz);
        } else {
          band_products(r.hi - r.lo, ex, ep, s.e1.data() + r.lo, s.c2.data() + r.lo, tx, ty, tz);
        }
        band_kernels::add_ends(a, b, r.a0, r.a1, r.b0, r.b1, tx, ty, tz, acc, acc + n, acc + 2 * n);
      }
      for (int i = q0; i < q1; ++i) {
        for (int c = 0; c < 3; ++c) y[3 * i + c] = acc[c * n + i];
      }
      if (!extra_column_.empty()) {
        for (int i = q0; i < q1; ++i) {
          for (int e = extra_start_[i]; e < extra_start_[i + 1]; ++e) {
            const Real* b = extra_value_.data() + 9 * static_cast<size_t>(e);
            const int j = extra_column_[e];
            const Real v0 = sp[j], v1 = sp[n + j], v2 = sp[2 * n + j];
            for (int c = 0; c < 3; ++c)
              y[3 * i + c] += b[3 * c] * v0 + b[3 * c + 1] * v1 + b[3 * c + 2] * v2;
          }
        }
      }
      if (filter.scale != nullptr) {
        for (int i = q0; i < q1; ++i) {
          if (filter.slot[i] < 0) continue;
          // y_i -> S y_i + c (S p_i) + (p_i - S p_i), with S p_i the filtered input kept in sp
          // (c times it: Eigen's (c S) p_i in the former ImplicitContact::filter_output
          // differed in the last bits for sliding contacts).
          const Real* f = filter.map + 9 * static_cast<size_t>(filter.slot[i]);
          const Real scale = filter.scale[filter.slot[i]];
          const Real y0 = y[3 * i], y1 = y[3 * i + 1], y2 = y[3 * i + 2];
          for (int c = 0; c < 3; ++c) {
            const Real sy = f[c] * y0 + (f[3 + c] * y1 + f[6 + c] * y2);
            const Real sq = sp[c * n + i];
            y[3 * i + c] = sy + scale * sq + (p[3 * i + c] - sq);
          }
        }
      }
    }
    seconds += std::chrono::duration<double>(Clock::now() - start).count();
    split_.record(part, seconds);  // (without the wait at the barrier)
    if (part == 0) parts_used = parts;
  });
  split_.update(parts_used);
}

}  // namespace jelly
