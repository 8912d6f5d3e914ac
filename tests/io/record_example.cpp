// Records the seed cube (n = 10) on the slope or the elevator, for trying the plotting scripts
// and ParaView before the `jelly` program exists:
//   build/tests/io/jelly_record_example out.h5 [slope|elevator] [seconds] [coulomb|seed]
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT.h5 [slope|elevator] [seconds] [coulomb|seed]\n", argv[0]);
    return 2;
  }
  const std::string terrain = argc > 2 ? argv[2] : "slope";
  const double seconds = argc > 3 ? std::atof(argv[3]) : 3.0;
  try {
    jelly::ContactParams contact;
    contact.model = jelly::contact_model_from_name(argc > 4 ? argv[4] : "coulomb", "contact");
    const jelly::Model model = jelly::build_cube(jelly::CubeSpec{});
    jelly::SimulatorOptions options;
    options.dt = 0.001;
    options.output_interval = 1.0 / 60;
    jelly::Simulator sim(model, jelly::rest_state(model), jelly::make_integrator("rk4"), options);
    if (terrain == "elevator") {
      sim.add_terrain(std::make_unique<jelly::Elevator>(jelly::ElevatorSpec{}, contact));
    } else {
      sim.add_terrain(std::make_unique<jelly::Plane>(jelly::Plane::slope(20, {}, contact)));
    }
    jelly::H5Recorder recorder(argv[1], sim);
    sim.add_observer(recorder);
    std::printf("%s\n", sim.run_until(seconds).brief().c_str());
  } catch (const jelly::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
