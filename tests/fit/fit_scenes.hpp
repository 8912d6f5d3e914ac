#pragma once
// Recordings with known coefficients for the fitting tests: a small cube deformed and spinning in
// free flight, and the same cube dropped onto the 20-degree slope (coulomb contact).
#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <random>

#include <jelly/fit/spring_fit.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly::testing {

inline constexpr Real kFitDt = 1e-3;
inline constexpr Real kFrameInterval = 0.01;  // 100 frames/s
inline constexpr Real kDuration = 0.5;
// Corner of the slope scene's cube: its lowest particle starts about 0.1 m above the slope.
inline const Vec3 kSlopeOrigin(-0.5, 0.35, -0.5);

// n^3 cube with the given coefficients per type (structural, shear, bending).
inline Model fit_cube(const std::array<SpringCoefficients, kSpringTypeCount>& springs,
                      Vec3 origin = Vec3(-0.5, 1, -0.5)) {
  CubeSpec spec = small_cube(3, 1, origin);
  spec.springs = springs;
  return build_cube(spec);
}

// Rest pose deformed (random displacements of 5 cm, a squash) and moving (random velocities of
// 0.5 m/s around a spin), so that every spring type is excited. Deterministic.
inline State excited_state(const Model& model, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(model);
  Vec3 centre = Vec3::Zero();
  for (int i = 0; i < model.num_particles(); ++i) centre += particle(s.x, i);
  centre /= model.num_particles();
  for (int i = 0; i < model.num_particles(); ++i) {
    Vec3 r = particle(s.x, i) - centre;
    r.y() *= 0.85;
    particle(s.x, i) = centre + r + 0.05 * Vec3(u(rng), u(rng), u(rng));
    particle(s.v, i) = Vec3(0, 0, 1.5).cross(r) + 0.5 * Vec3(u(rng), u(rng), u(rng));
  }
  return s;
}

inline TerrainFactory slope_terrain() {
  return [] {
    Terrains terrains;
    terrains.push_back(std::make_unique<Plane>(Plane::slope(20)));
    return terrains;
  };
}

// Free flight: no terrain.
inline Trajectory free_recording(const Model& model, bool velocities = true) {
  return simulate_trajectory(model, excited_state(model), {}, "rk4", kFitDt, kFrameInterval,
                             kDuration, velocities);
}

// The cube (built at kSlopeOrigin) lands on the slope after about 0.15 s and slides.
inline Trajectory slope_recording(const Model& model) {
  return simulate_trajectory(model, excited_state(model), slope_terrain(), "rk4", kFitDt,
                             kFrameInterval, kDuration);
}

inline void add_noise(Trajectory& trajectory, Real sigma, unsigned seed = 11) {
  std::mt19937 rng(seed);
  std::normal_distribution<Real> normal(0, sigma);
  for (VecX& x : trajectory.positions)
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += normal(rng);
}

}  // namespace jelly::testing
