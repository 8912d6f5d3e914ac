// Loads a scene, runs it and prints the centre of mass:
//   consumer SCENE.json [DURATION] [--vortex SWIRL] [--ripple AMPLITUDE]
// --vortex adds a force of one's own (vortex_force.hpp) about the vertical axis through the
// origin; --ripple adds a terrain of one's own (ripple_floor.hpp), a rippled floor at y = 0.
#include <cstdio>
#include <memory>
#include <string>

#include <jelly/jelly.hpp>

#include "ripple_floor.hpp"
#include "vortex_force.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SCENE.json [DURATION] [--vortex S] [--ripple A]\n");
    return 2;
  }
  try {
    jelly::Scene scene = jelly::load_scene(argv[1]);
    double vortex = 0, ripple = 0;
    for (int i = 2; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--vortex" && i + 1 < argc) {
        vortex = std::stod(argv[++i]);
      } else if (arg == "--ripple" && i + 1 < argc) {
        ripple = std::stod(argv[++i]);
      } else {
        scene.duration = std::stod(arg);
      }
    }
    jelly::Simulator sim = jelly::make_simulator(scene);
    if (vortex != 0) {
      sim.add_force(
          std::make_shared<VortexForce>(sim.model(), Eigen::Vector3d::Zero(), vortex, 0.5));
    }
    if (ripple != 0) sim.add_terrain(std::make_unique<RippleFloor>(ripple, 2.0));
    const jelly::RunReport report = sim.run_until(scene.duration);
    const Eigen::Vector3d com = jelly::center_of_mass(sim.model(), sim.state());
    std::printf("%s\ncentre of mass: %.4f %.4f %.4f\n", report.brief().c_str(), com.x(), com.y(),
                com.z());
    for (const std::string& note : report.notes) std::printf("note: %s\n", note.c_str());
    return report.ok() ? 0 : 3;
  } catch (const jelly::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
