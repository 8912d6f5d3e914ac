#pragma once
// Forces from outside the bodies, applied at every force evaluation besides gravity and the
// springs: a constant force spread over a body by mass, wind (drag towards the air's velocity)
// and point forces on chosen particles; each may vary in time by a sinusoidal gust factor and be
// limited to a time window.
#include <limits>
#include <string_view>
#include <vector>

#include <jelly/core/enum_names.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

enum class ExternalForceKind {
  kConstant,  // `vector` (N, the total) spread over the particles in proportion to their masses
  kWind,      // drag (w(t) - v) on each particle, w(t) the air's velocity (`vector`, m/s)
  kPoint,     // `vector` (N) on each particle
};
// Every kind with its scene name and description.
const std::vector<EnumName<ExternalForceKind>>& external_force_kinds();
std::string_view external_force_kind_name(ExternalForceKind kind);
// Throws InputError naming `field` for an unknown name.
ExternalForceKind external_force_kind_from_name(std::string_view name, std::string_view field);

struct ExternalForce {
  ExternalForceKind kind = ExternalForceKind::kConstant;
  std::vector<int> particles;  // global particle indices it acts on
  Vec3 vector = Vec3::Zero();  // force (N) or, for wind, air velocity (m/s)
  Real drag = 0;               // wind: N s/m per particle, >= 0
  Real gust = 0;               // vector(t) = vector (1 + gust sin(2 pi gust_frequency t))
  Real gust_frequency = 0;     // Hz, >= 0
  Real start = 0;              // acts for start <= t < end
  Real end = std::numeric_limits<Real>::infinity();

  Vec3 vector_at(Real t) const;
  // Throws InputError naming `prefix`field for a value out of range.
  void validate(int num_particles, const std::string& prefix) const;
};

// f += the external forces at time t on velocities v. `mass` is the model's [N] masses.
void add_external_forces(const std::vector<ExternalForce>& forces, const VecX& mass, Real t,
                         const VecX& v, VecX& f);
// d(f)/d(v) of the external forces is diagonal: damping[i] += drag for each wind particle i
// active at time t (damping has one entry per particle).
void add_external_damping(const std::vector<ExternalForce>& forces, Real t, VecX& damping);

}  // namespace jelly
