#include <jelly/core/model.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly {

int Model::add_body(const std::string& name, BodyPart part, Real radius) {
  require(!name.empty(), "body.name", "\"\"", "a non-empty name");
  require(find_body(name) == nullptr, "body.name", "\"" + name + "\"",
          "a name no other body of the model has");
  const int n = part.num_particles();
  require(n > 0, "bodies." + name + ".particles", n, "at least one particle");
  require(part.position.size() == 3 * n, "bodies." + name + ".position.size", part.position.size(),
          "3 x the number of particles");
  const int first = num_particles();
  Body body;
  body.name = name;
  body.kind = part.kind;
  body.first_particle = first;
  body.num_particles = n;
  body.first_spring = springs.size();
  body.num_springs = part.springs.size();
  body.spacing = part.spacing;
  body.radius = radius > 0 ? radius : 0.5 * part.spacing;
  body.thickness = part.sheet ? body.radius : 0;
  body.surface = std::move(part.surface);
  body.surface.shift_particles(first);
  body.groups = std::move(part.groups);
  for (ParticleGroup& g : body.groups) {
    for (int& p : g.particles) p += first;
  }
  body.volume = std::move(part.volume);
  body.volume.shift_particles(first);

  mass.conservativeResize(first + n);
  mass.tail(n) = part.mass;
  rest_position.conservativeResize(3 * (first + n));
  rest_position.tail(3 * n) = part.position;
  springs.append(part.springs, first);
  bodies.push_back(std::move(body));
  return num_bodies() - 1;
}

void VolumeElements::shift_particles(int offset) {
  for (auto& c : cells) {
    for (int& p : c) p += offset;
  }
  for (auto& t : tets) {
    for (int& p : t) p += offset;
  }
}

const Body* Model::find_body(std::string_view name) const {
  for (const Body& b : bodies) {
    if (b.name == name) return &b;
  }
  return nullptr;
}

const Body& Model::body_of(int particle) const {
  for (const Body& b : bodies) {
    if (b.contains(particle)) return b;
  }
  throw InputError("particle", std::to_string(particle), "a particle of one of the bodies");
}

void Model::validate() const {
  const int n = num_particles();
  // (A field's name is built only for a message: a million springs are checked in milliseconds.)
  for (int i = 0; i < n; ++i) {
    const bool ok = std::isfinite(mass[i]) && mass[i] > 0;
    if (!ok) require(ok, "mass[" + std::to_string(i) + "]", mass[i], "a finite mass > 0");
  }
  require(rest_position.size() == 3 * n, "rest_position.size", rest_position.size(),
          "3 x the number of particles");
  require(gravity.allFinite(), "gravity", gravity.transpose(), "finite components");
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const std::string at = "bodies[" + std::to_string(k) + "].";
    require(bodies[k].velocity.allFinite(), at + "velocity", bodies[k].velocity.transpose(),
            "finite components (m/s)");
    require(bodies[k].angular_velocity.allFinite(), at + "angular_velocity",
            bodies[k].angular_velocity.transpose(), "finite components (rad/s)");
  }
  for (int s = 0; s < springs.size(); ++s) {
    const int a = springs.a[s], b = springs.b[s];
    const Real l0 = springs.rest_length[s], ks = springs.ks[s], kd = springs.kd[s];
    const bool a_ok = a >= 0 && a < n, b_ok = b >= 0 && b < n && b != a;
    const bool l0_ok = std::isfinite(l0) && l0 > 0;
    const bool ks_ok = std::isfinite(ks) && ks >= 0, kd_ok = std::isfinite(kd) && kd >= 0;
    if (a_ok && b_ok && l0_ok && ks_ok && kd_ok) continue;
    const std::string at = "springs[" + std::to_string(s) + "]";
    require(a_ok, at + ".a", a, "a particle index in [0, " + std::to_string(n) + ")");
    require(b_ok, at + ".b", b, "a particle index in [0, N) other than a");
    require(l0_ok, at + ".rest_length", l0, "a finite length > 0");
    require(ks_ok, at + ".ks", ks, "a finite stiffness >= 0");
    require(kd_ok, at + ".kd", kd, "a finite damping >= 0");
  }
  // Bodies, when there are any, cover the particles and springs in order.
  int next_particle = 0, next_spring = 0;
  for (const Body& b : bodies) {
    const std::string at = "bodies." + b.name;
    require(b.first_particle == next_particle && b.num_particles > 0, at + ".first_particle",
            b.first_particle, "the particles after the previous body's");
    require(b.first_spring == next_spring && b.num_springs >= 0, at + ".first_spring",
            b.first_spring, "the springs after the previous body's");
    next_particle = b.end_particle();
    next_spring = b.end_spring();
    b.surface.validate(n, at + ".surface");
  }
  if (!bodies.empty()) {
    require(next_particle == n, "bodies", next_particle, "bodies covering all particles");
    require(next_spring == springs.size(), "bodies", next_spring, "bodies covering all springs");
  }
  pins.validate(n);
  for (std::size_t k = 0; k < external_forces.size(); ++k) {
    external_forces[k].validate(n, "external_forces[" + std::to_string(k) + "].");
  }
}

State initial_state(const Model& model) {
  State state = rest_state(model);
  for (const Body& b : model.bodies) {
    if (b.velocity.isZero() && b.angular_velocity.isZero()) continue;
    Vec3 center = Vec3::Zero();
    Real mass = 0;
    for (int i = b.first_particle; i < b.end_particle(); ++i) {
      center += model.mass[i] * particle(model.rest_position, i);
      mass += model.mass[i];
    }
    center /= mass;
    for (int i = b.first_particle; i < b.end_particle(); ++i)
      particle(state.v, i) =
          b.velocity + b.angular_velocity.cross(particle(model.rest_position, i) - center);
  }
  return state;
}

State rest_state(const Model& model) {
  State state;
  state.t = 0;
  state.x = model.rest_position;
  state.v = VecX::Zero(model.num_dofs());
  return state;
}

}  // namespace jelly
