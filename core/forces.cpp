#include <jelly/core/forces.hpp>

#include <cmath>

namespace jelly {

void add_spring_forces(const Model& model, const VecX& x, const VecX& v, VecX& f) {
  const Springs& s = model.springs;
  const int count = s.size();
  const int* a = s.a.data();
  const int* b = s.b.data();
  const Real* rest = s.rest_length.data();
  const Real* ks = s.ks.data();
  const Real* kd = s.kd.data();
  const Real* px = x.data();
  const Real* pv = v.data();
  const Real* pr = model.rest_position.data();
  Real* pf = f.data();
  for (int k = 0; k < count; ++k) {
    const int ia = 3 * a[k];
    const int ib = 3 * b[k];
    Real dx = px[ia] - px[ib];
    Real dy = px[ia + 1] - px[ib + 1];
    Real dz = px[ia + 2] - px[ib + 2];
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
    const Real closing =
        (pv[ia] - pv[ib]) * ux + (pv[ia + 1] - pv[ib + 1]) * uy + (pv[ia + 2] - pv[ib + 2]) * uz;
    const Real magnitude = -ks[k] * (length - rest[k]) - kd[k] * closing;
    const Real fx = magnitude * ux, fy = magnitude * uy, fz = magnitude * uz;
    pf[ia] += fx;
    pf[ia + 1] += fy;
    pf[ia + 2] += fz;
    pf[ib] -= fx;
    pf[ib + 1] -= fy;
    pf[ib + 2] -= fz;
  }
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
