#pragma once
// The scenes jelly-bench measures: the seed cube (any n, seed pose) on the 20-degree slope or on
// the seed elevator, and a contact-free deformed, spinning jelly for accuracy, each with the
// energy cap of its divergence guard (docs/benchmarking.md).
#include <memory>
#include <string>
#include <vector>

#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly::bench {

struct SceneSpec {
  std::string name = "slope";  // "slope", "elevator" or "free"
  int n = 10;                  // particles per edge (edge length 4, seed pose)
  Real ks = 1400;              // N/m, every spring type
  Real kd = 50;                // N s/m, every spring type
  ContactModel contact = ContactModel::kCoulomb;
};

// Throws jelly::InputError for an unknown scene name.
void validate_scene_name(const std::string& name);

// The model, initial state and terrains of a scene. "free": the cube without gravity or terrain,
// stretched by 10 % along x, sheared, and spinning at 2 rad/s about a tilted axis.
struct SceneParts {
  Model model;
  State state;
  Terrains terrains;
};
SceneParts build_scene(const SceneSpec& spec);

// Cap on the total energy (J) over [state.t, state.t + horizon]:
//   E0 + W + tolerance * (K0 + U0 + M |g| L)
// with E0, K0, U0 the initial total, kinetic and elastic energies, M the total mass, L the
// diagonal of the jelly's bounding box, and W = M (|g| dh + 2 V u + 2 V^2) a bound on the work a
// moving terrain does in one impact per particle: dh its largest rise against gravity, V its
// largest speed over the horizon (both sampled at 1 ms), u = sqrt(v0^2 + 2 |g| H) the largest
// arrival speed (v0 the fastest initial particle, H the drop from the jelly's top to the
// terrain's lowest point). W = 0 for fixed terrains.
Real energy_cap(const SceneParts& parts, Real horizon, Real tolerance);

// A simulator of the scene with `integrator`, time step dt and the divergence guard whose energy
// cap is energy_cap(parts, horizon, energy_tolerance) (no energy check when the tolerance is < 0).
Simulator make_scene_simulator(const SceneSpec& spec, const std::string& integrator, Real dt,
                               Real horizon, Real energy_tolerance);

}  // namespace jelly::bench
