#pragma once
// Energies, momenta and centre of mass of a model in a state.
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>

namespace jelly {

Real kinetic_energy(const Model& model, const VecX& v);        // sum m |v|^2 / 2
Real elastic_energy(const Model& model, const VecX& x);        // sum ks (|xa - xb| - l0)^2 / 2
Real gravitational_energy(const Model& model, const VecX& x);  // -sum m g . x
Vec3 center_of_mass(const Model& model, const VecX& x);        // sum m x / sum m
Vec3 linear_momentum(const Model& model, const VecX& v);       // sum m v
Vec3 angular_momentum(const Model& model, const VecX& x, const VecX& v);  // sum m x cross v

// kinetic_energy of a state.
inline Real kinetic_energy(const Model& m, const State& s) { return kinetic_energy(m, s.v); }
// elastic_energy of a state.
inline Real elastic_energy(const Model& m, const State& s) { return elastic_energy(m, s.x); }
// gravitational_energy of a state.
inline Real gravitational_energy(const Model& m, const State& s) {
  return gravitational_energy(m, s.x);
}
// center_of_mass of a state.
inline Vec3 center_of_mass(const Model& m, const State& s) { return center_of_mass(m, s.x); }
// linear_momentum of a state.
inline Vec3 linear_momentum(const Model& m, const State& s) { return linear_momentum(m, s.v); }
// angular_momentum of a state.
inline Vec3 angular_momentum(const Model& m, const State& s) {
  return angular_momentum(m, s.x, s.v);
}
// Kinetic + elastic + gravitational.
inline Real total_energy(const Model& m, const State& s) {
  return kinetic_energy(m, s.v) + elastic_energy(m, s.x) + gravitational_energy(m, s.x);
}

// How much a body is crushed at x: the signed volumes of its volume elements (Body::volume; a
// lattice cell's as the sum of the six tetrahedra around its diagonal from corner 0 to 7)
// against the same at the rest positions. An element is inverted when its signed volume has
// lost the sign it has at rest, or is 0.
struct BodyVolume {
  long elements = 0;  // cells or tetrahedra; 0: a body without volume (a cloth)
  long inverted = 0;  // elements whose signed volume lost its rest sign, or is 0
  Real rest = 0;      // m^3, the sum of the elements' signed volumes at rest
  Real current = 0;   // m^3, the same at x

  // False for a body without volume (a cloth).
  bool has_volume() const { return elements > 0 && rest != 0; }
  // Current over rest volume; 1 without volume.
  Real ratio() const { return has_volume() ? current / rest : 1; }
  // The share of inverted elements.
  Real inverted_fraction() const { return elements > 0 ? Real(inverted) / elements : 0; }
};
// No allocation; O(elements).
BodyVolume body_volume(const Model& model, const Body& body, const VecX& x);

// elastic_energy on up to `threads` threads, its terms summed in fixed chunks: the same value
// for any thread count (rounded unlike the one-loop sum above).
Real elastic_energy(const Model& model, const VecX& x, int threads);
// The total energy in the frame moving with velocity u at time t (elastic and gravitational at
// x - u t, kinetic of v - u), on up to `threads` threads: the same value for any thread count.
// Contact's restitution budgets compare it before and after a step.
Real energy_in_frame(const Model& model, const VecX& x, const VecX& v, const Vec3& u, Real t,
                     int threads);

}  // namespace jelly
