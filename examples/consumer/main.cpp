// Loads a scene, runs it and prints the centre of mass: consumer SCENE.json [DURATION]
#include <cstdio>
#include <string>

#include <jelly/jelly.hpp>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SCENE.json [DURATION]\n");
    return 2;
  }
  try {
    jelly::Scene scene = jelly::load_scene(argv[1]);
    if (argc > 2) scene.duration = std::stod(argv[2]);
    jelly::Simulator sim = jelly::make_simulator(scene);
    const jelly::RunReport report = sim.run_until(scene.duration);
    const Eigen::Vector3d com = jelly::center_of_mass(sim.model(), sim.state());
    std::printf("%s\ncentre of mass: %.4f %.4f %.4f\n", report.brief().c_str(), com.x(), com.y(),
                com.z());
    return report.ok() ? 0 : 3;
  } catch (const jelly::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
