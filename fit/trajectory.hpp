#pragma once
// A recorded trajectory of a jelly (frames of positions, optionally velocities) together with
// everything needed to replay it: the model's structure, the terrains and the integrator and dt.
#include <functional>
#include <string>
#include <vector>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/solvers/contact/body_contact_params.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

// Builds a fresh set of terrains for one replay (the Simulator owns its terrains). It may be
// called from several threads at once, so it must not share mutable state.
using TerrainFactory = std::function<Terrains()>;

struct Trajectory {
  // Masses, springs (a, b, rest length, type) and gravity. The coefficients ks and kd are the
  // starting guess of a fit unless FitOptions::initial names other values.
  Model model;
  std::vector<Real> times;       // [T] s, strictly increasing
  std::vector<VecX> positions;   // [T] frames of 3N positions (m)
  std::vector<VecX> velocities;  // empty, or [T] frames of 3N velocities (m/s)
  TerrainFactory terrains;       // empty = no terrain
  // Contact between bodies (and within one) as the recording ran it; every replay uses it.
  BodyContactParams body_contact;
  std::string integrator = "rk4";  // the integrator the recording was made with
  IntegratorOptions integrator_options;
  Real dt = 0.001;  // s; every frame interval is a whole number of steps

  int frames() const { return static_cast<int>(times.size()); }
  bool has_velocities() const { return !velocities.empty(); }
  // Throws InputError naming the first problem: fewer than 3 frames, sizes, times that are not
  // increasing or not a whole number of steps apart, non-finite values, a recording in which
  // nothing moves or no spring ever changes length (nothing to identify).
  void validate() const;
  // Frame k as a state to restart from: recorded velocities when present, else finite
  // differences of the positions (second order: central inside, one-sided at both ends).
  State state(int k) const;
  // The terrains of one replay (none when `terrains` is empty).
  Terrains make_terrains() const;
};

// Simulates `model` from `initial` with the named integrator (also implicit_euler_ceres) and
// records a frame every `frame_interval` (a whole number of steps) until `duration`: a
// synthetic recording with known coefficients, as the tests use.
Trajectory simulate_trajectory(const Model& model, const State& initial, TerrainFactory terrains,
                               const std::string& integrator, Real dt, Real frame_interval,
                               Real duration, bool record_velocities = true,
                               const IntegratorOptions& integrator_options = {},
                               const BodyContactParams& body_contact = {});

}  // namespace jelly
