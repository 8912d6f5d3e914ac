#include <jelly/core/detail/forces.hpp>

#include <cmath>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

void add_spring_forces(const Model& model, const VecX& x, const VecX& v, VecX& f) {
  const Springs& s = model.springs;
  const int count = s.size();
  if (count == 0) return;
  const int* a = s.a.data();
  const int* b = s.b.data();
  const Real* rest = s.rest_length.data();
  const Real* ks = s.ks.data();
  const Real* kd = s.kd.data();
  const Real* px = x.data();
  const Real* pv = v.data();
  const Real* pr = model.rest_position.data();
  Real* pf = f.data();
  // Springs are stored grouped by their first particle (build_cube does so): while a repeats, its
  // position and velocity stay in registers and its force is summed there, which halves the
  // memory operations per spring (the loop is bound by them, not by sqrt). Any order stays
  // correct: a change of a flushes the sum and reloads.
  int current = 3 * a[0];
  Real sum_x = 0, sum_y = 0, sum_z = 0;
  Real xa = px[current], ya = px[current + 1], za = px[current + 2];
  Real ua = pv[current], va = pv[current + 1], wa = pv[current + 2];
  for (int k = 0; k < count; ++k) {
    const int ia = 3 * a[k];
    const int ib = 3 * b[k];
    if (ia != current) {
      pf[current] += sum_x;
      pf[current + 1] += sum_y;
      pf[current + 2] += sum_z;
      sum_x = sum_y = sum_z = 0;
      current = ia;
      xa = px[ia], ya = px[ia + 1], za = px[ia + 2];
      ua = pv[ia], va = pv[ia + 1], wa = pv[ia + 2];
    }
    Real dx = xa - px[ib];
    Real dy = ya - px[ib + 1];
    Real dz = za - px[ib + 2];
    const Real length = std::sqrt(dx * dx + dy * dy + dz * dz);
    Real inv = 1.0 / length;
    if (!(length > kDegenerateLength * rest[k])) {
      // Coincident particles (e.g. two projected onto one contact point): no direction, so the
      // spring pushes along its rest direction instead of producing NaN.
      dx = pr[ia] - pr[ib];
      dy = pr[ia + 1] - pr[ib + 1];
      dz = pr[ia + 2] - pr[ib + 2];
      inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    }
    const Real ux = dx * inv, uy = dy * inv, uz = dz * inv;
    const Real closing = (ua - pv[ib]) * ux + (va - pv[ib + 1]) * uy + (wa - pv[ib + 2]) * uz;
    const Real magnitude = -ks[k] * (length - rest[k]) - kd[k] * closing;
    const Real fx = magnitude * ux, fy = magnitude * uy, fz = magnitude * uz;
    sum_x += fx;
    sum_y += fy;
    sum_z += fz;
    pf[ib] -= fx;
    pf[ib + 1] -= fy;
    pf[ib + 2] -= fz;
  }
  pf[current] += sum_x;
  pf[current + 1] += sum_y;
  pf[current + 2] += sum_z;
}

void divide_by_masses(const Model& model, VecX& f, int threads) {
  const Real* m = model.mass.data();
  Real* pf = f.data();
  parallel::for_ranges(
      threads, model.num_particles(),
      [&](long begin, long end) {
        for (long i = begin; i < end; ++i) {
          const Real inv = 1.0 / m[i];
          pf[3 * i] *= inv;
          pf[3 * i + 1] *= inv;
          pf[3 * i + 2] *= inv;
        }
      },
      parallel::kMinParticlesPerThread);
}

void compute_forces(const Model& model, const VecX& x, const VecX& v, VecX& f) {
  const int n = model.num_particles();
  const Real* m = model.mass.data();
  Real* pf = f.data();
  const Real gx = model.gravity.x(), gy = model.gravity.y(), gz = model.gravity.z();
  for (int i = 0; i < n; ++i) {
    pf[3 * i] = m[i] * gx;
    pf[3 * i + 1] = m[i] * gy;
    pf[3 * i + 2] = m[i] * gz;
  }
  add_spring_forces(model, x, v, f);
}

}  // namespace jelly
