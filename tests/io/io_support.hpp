#pragma once
// Scenes and helpers shared by the io tests.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"
#include "support/temp_dir.hpp"

namespace jelly::testing {

// A small cube dropped onto the seed's 20-degree slope, with the given contact model.
inline Simulator slope_sim(ContactModel contact_model = ContactModel::kCoulomb, int n = 3,
                           const std::string& integrator = "rk4", Real output_interval = 0.02) {
  const Model m = build_cube(small_cube(n, 1.0, Vec3(-0.5, 0.4, -0.5)));
  Simulator sim = make_sim(m, rest_state(m), integrator, 1e-3, output_interval);
  ContactParams contact;
  contact.model = contact_model;
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20, Vec3::Zero(), contact)));
  return sim;
}

inline bool python_has(const std::string& module) {
  const std::string command = "/usr/bin/python3 -c 'import " + module + "' >/dev/null 2>&1";
  return std::filesystem::exists("/usr/bin/python3") && std::system(command.c_str()) == 0;
}

}  // namespace jelly::testing
