#include <jelly/core/measures.hpp>

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

Real kinetic_energy(const Model& model, const VecX& v) {
  Real e = 0;
  for (int i = 0; i < model.num_particles(); ++i)
    e += 0.5 * model.mass[i] * particle(v, i).squaredNorm();
  return e;
}

namespace {
// The energy ks (|xa - xb| - l0)^2 / 2 of springs [begin, end), summed in order.
Real springs_energy(const Springs& s, const VecX& x, long begin, long end) {
  Real e = 0;
  for (long k = begin; k < end; ++k) {
    const Real stretch = (particle(x, s.a[k]) - particle(x, s.b[k])).norm() - s.rest_length[k];
    e += 0.5 * s.ks[k] * stretch * stretch;
  }
  return e;
}
}  // namespace

namespace {
Real signed_six_volume(const VecX& x, int a, int b, int c, int d) {
  const Vec3 pa = particle(x, a);
  return (particle(x, b) - pa).dot((particle(x, c) - pa).cross(particle(x, d) - pa));
}

// Six times a lattice cell's signed volume: the six tetrahedra around its diagonal 0-7, the
// corners 1, 3, 2, 6, 4, 5 taken in turn around it (each positive for an undeformed cell).
Real cell_six_volume(const VecX& x, const std::array<int, 8>& c) {
  constexpr int kRing[7] = {1, 3, 2, 6, 4, 5, 1};
  Real v = 0;
  for (int t = 0; t < 6; ++t) v += signed_six_volume(x, c[0], c[kRing[t]], c[kRing[t + 1]], c[7]);
  return v;
}
}  // namespace

BodyVolume body_volume(const Model& model, const Body& body, const VecX& x) {
  BodyVolume out;
  const VolumeElements& e = body.volume;
  out.elements = e.size();
  const auto add = [&](Real rest6, Real now6) {
    out.rest += rest6 / 6;
    out.current += now6 / 6;
    if (!(now6 * rest6 > 0)) ++out.inverted;
  };
  for (const auto& c : e.cells) add(cell_six_volume(model.rest_position, c), cell_six_volume(x, c));
  for (const auto& t : e.tets) {
    add(signed_six_volume(model.rest_position, t[0], t[1], t[2], t[3]),
        signed_six_volume(x, t[0], t[1], t[2], t[3]));
  }
  return out;
}

Real elastic_energy(const Model& model, const VecX& x) {
  return springs_energy(model.springs, x, 0, model.springs.size());
}

Real elastic_energy(const Model& model, const VecX& x, int threads) {
  thread_local std::vector<Real> partials;  // no allocation once sized
  return parallel::ordered_sum(threads, model.springs.size(), partials, [&](long begin, long end) {
    return springs_energy(model.springs, x, begin, end);
  });
}

Real energy_in_frame(const Model& model, const VecX& x, const VecX& v, const Vec3& u, Real t,
                     int threads) {
  Real e = elastic_energy(model, x, threads) + gravitational_energy(model, x) +
           t * model.mass.sum() * model.gravity.dot(u);
  for (int i = 0; i < model.num_particles(); ++i)
    e += 0.5 * model.mass[i] * (particle(v, i) - u).squaredNorm();
  return e;
}

Real gravitational_energy(const Model& model, const VecX& x) {
  Real e = 0;
  for (int i = 0; i < model.num_particles(); ++i)
    e -= model.mass[i] * model.gravity.dot(particle(x, i));
  return e;
}

Vec3 center_of_mass(const Model& model, const VecX& x) {
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < model.num_particles(); ++i) sum += model.mass[i] * particle(x, i);
  return sum / model.mass.sum();
}

Vec3 linear_momentum(const Model& model, const VecX& v) {
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < model.num_particles(); ++i) p += model.mass[i] * particle(v, i);
  return p;
}

Vec3 angular_momentum(const Model& model, const VecX& x, const VecX& v) {
  Vec3 l = Vec3::Zero();
  for (int i = 0; i < model.num_particles(); ++i)
    l += model.mass[i] * Vec3(particle(x, i)).cross(Vec3(particle(v, i)));
  return l;
}

}  // namespace jelly
