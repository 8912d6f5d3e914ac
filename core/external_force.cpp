#include <jelly/core/model.hpp>

#include <cmath>
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly {

const std::vector<EnumName<ExternalForceKind>>& external_force_kinds() {
  static const std::vector<EnumName<ExternalForceKind>> table{
      {ExternalForceKind::kConstant, "constant",
       "force (N, the total) spread over the particles by mass: force"},
      {ExternalForceKind::kWind, "wind",
       "drag (velocity - v) on each particle: velocity (m/s), drag (N s/m)"},
      {ExternalForceKind::kPoint, "point", "force (N) on each chosen particle: force"},
  };
  return table;
}

std::string_view external_force_kind_name(ExternalForceKind kind) {
  return name_of(external_force_kinds(), kind);
}

ExternalForceKind external_force_kind_from_name(std::string_view name, std::string_view field) {
  return value_of(external_force_kinds(), name, field);
}

Vec3 ExternalForce::vector_at(Real t) const {
  if (gust == 0) return vector;
  return vector * (1 + gust * std::sin(2 * M_PI * gust_frequency * t));
}

void ExternalForce::validate(int num_particles, const std::string& prefix) const {
  require(!particles.empty(), prefix + "particles", "[]", "at least one particle");
  for (int p : particles) {
    require(p >= 0 && p < num_particles, prefix + "particles", p,
            "particle indices in [0, " + std::to_string(num_particles) + ")");
  }
  require(vector.allFinite(), prefix + (kind == ExternalForceKind::kWind ? "velocity" : "force"),
          vector.transpose(), "finite components");
  require(std::isfinite(drag) && drag >= 0, prefix + "drag", drag, "a finite drag >= 0 N s/m");
  require(std::isfinite(gust), prefix + "gust", gust, "a finite relative amplitude");
  require(std::isfinite(gust_frequency) && gust_frequency >= 0, prefix + "gust_frequency",
          gust_frequency, "a finite frequency >= 0 Hz");
  require(std::isfinite(start) && start >= 0, prefix + "start", start, "a finite time >= 0 s");
  require(!std::isnan(end) && end > start, prefix + "end", end, "a time after start (or inf)");
}

void add_external_forces(const std::vector<ExternalForce>& forces, const VecX& mass, Real t,
                         const VecX& v, VecX& f) {
  for (const ExternalForce& e : forces) {
    if (t < e.start || t >= e.end) continue;
    const Vec3 w = e.vector_at(t);
    switch (e.kind) {
      case ExternalForceKind::kConstant: {
        Real total = 0;
        for (int i : e.particles) total += mass[i];
        for (int i : e.particles) particle(f, i) += (mass[i] / total) * w;
        break;
      }
      case ExternalForceKind::kWind:
        for (int i : e.particles) particle(f, i) += e.drag * (w - particle(v, i));
        break;
      case ExternalForceKind::kPoint:
        for (int i : e.particles) particle(f, i) += w;
        break;
    }
  }
}

void add_external_damping(const std::vector<ExternalForce>& forces, Real t, VecX& damping) {
  for (const ExternalForce& e : forces) {
    if (e.kind != ExternalForceKind::kWind || t < e.start || t >= e.end) continue;
    for (int i : e.particles) damping[i] += e.drag;
  }
}

}  // namespace jelly
