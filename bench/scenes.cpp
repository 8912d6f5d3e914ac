#include <jelly/bench/scenes.hpp>

#include <Eigen/Geometry>
#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly::bench {

void validate_scene_name(const std::string& name) {
  require(name == "slope" || name == "elevator" || name == "free", "scene", name,
          "one of slope, elevator, free");
}

SceneParts build_scene(const SceneSpec& spec) {
  validate_scene_name(spec.name);
  CubeSpec cube;
  cube.n = spec.n;
  for (auto& c : cube.springs) c = SpringCoefficients{spec.ks, spec.kd};
  if (spec.name == "free") cube.gravity.setZero();
  SceneParts parts;
  parts.model = build_cube(cube);
  parts.state = rest_state(parts.model);
  ContactParams contact;
  contact.model = spec.contact;
  if (spec.name == "slope") {
    parts.terrains.push_back(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
  } else if (spec.name == "elevator") {
    parts.terrains.push_back(std::make_unique<Elevator>(ElevatorSpec{}, contact));
  } else {
    // Deformed (stretch 1.1 along x, shear 0.05 of y into x) and spinning about a tilted axis
    // through the centre of mass, plus a small smooth velocity field that excites many modes.
    const Vec3 c = center_of_mass(parts.model, parts.state);
    const Vec3 omega = 2.0 * Vec3(0.3, 1.0, 0.2).normalized();
    for (int i = 0; i < parts.model.num_particles(); ++i) {
      const Vec3 r = particle(parts.state.x, i) - c;
      const Vec3 deformed(1.1 * r.x() + 0.05 * r.y(), r.y(), r.z());
      particle(parts.state.x, i) = c + deformed;
      particle(parts.state.v, i) =
          omega.cross(deformed) +
          0.1 * Vec3(std::sin(1.3 * i), std::cos(0.7 * i), std::sin(0.9 * i));
    }
    // Remove the net momentum so that the jelly spins in place.
    const Vec3 p = linear_momentum(parts.model, parts.state) / parts.model.mass.sum();
    for (int i = 0; i < parts.model.num_particles(); ++i) particle(parts.state.v, i) -= p;
  }
  return parts;
}

Real energy_cap(const SceneParts& parts, Real horizon, Real tolerance) {
  const Model& m = parts.model;
  const State& s = parts.state;
  const Real mass = m.mass.sum();
  const Real g = m.gravity.norm();
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (int i = 0; i < m.num_particles(); ++i) {
    lo = lo.cwiseMin(Vec3(particle(s.x, i)));
    hi = hi.cwiseMax(Vec3(particle(s.x, i)));
  }
  const Real size = (hi - lo).norm();
  Real work = 0;
  const Vec3 up = g > 0 ? Vec3(-m.gravity / g) : Vec3::Zero();
  Real top = -INFINITY, fastest = 0;
  for (int i = 0; i < m.num_particles(); ++i) {
    top = std::max(top, up.dot(particle(s.x, i)));
    fastest = std::max(fastest, particle(s.v, i).norm());
  }
  for (const auto& terrain : parts.terrains) {
    const Vec3 start = terrain->position(s.t);
    Real rise = 0, speed = 0, lowest = INFINITY;
    const int samples = static_cast<int>(std::ceil(horizon / 1e-3)) + 1;
    for (int k = 0; k <= samples; ++k) {
      const Real t = s.t + horizon * k / samples;
      const Vec3 p = terrain->position(t);
      rise = std::max(rise, (p - start).dot(up));
      lowest = std::min(lowest, p.dot(up));
      speed = std::max(speed, terrain->surface_velocity(p, t).norm());
    }
    if (speed == 0) continue;  // a fixed terrain does no work
    // An impact (restitution <= 1) on a surface moving at speed <= V leaves the relative speed no
    // larger, so a particle arriving at speed u leaves at most at u + 2V: its kinetic energy per
    // unit mass grows by at most 2 V u + 2 V^2, with u bounded by a fall from the jelly's top to
    // the terrain's lowest point.
    const Real drop = std::max<Real>(0, top - lowest);
    const Real arrival = std::sqrt(fastest * fastest + 2 * g * drop);
    work += mass * (g * rise + 2 * speed * arrival + 2 * speed * speed);
  }
  const Real scale = kinetic_energy(m, s) + elastic_energy(m, s) + mass * g * size;
  return total_energy(m, s) + work + tolerance * scale;
}

Simulator make_scene_simulator(const SceneSpec& spec, const std::string& integrator, Real dt,
                               Real horizon, Real energy_tolerance) {
  SceneParts parts = build_scene(spec);
  SimulatorOptions options;
  options.dt = dt;
  options.output_interval = horizon + 1;  // no observers: frames are irrelevant
  if (energy_tolerance >= 0) {
    options.divergence.max_energy = energy_cap(parts, horizon, energy_tolerance);
  }
  Simulator sim(std::move(parts.model), std::move(parts.state), make_integrator(integrator),
                options);
  for (auto& t : parts.terrains) sim.add_terrain(std::move(t));
  return sim;
}

}  // namespace jelly::bench
