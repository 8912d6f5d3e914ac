// Runs the seed cube (n = 10) on the 20 degree slope or on the elevator with one integrator and
// prints the run report and the integrator's statistics: the figures of docs/arkode.md.
//   jelly_arkode_bench <slope|elevator> <integrator> <dt> <t_end> [rtol] [atol] [schur|klu]
#include <cstdlib>
#include <iostream>
#include <string>

#include <jelly/jelly.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

int main(int argc, char** argv) {
  const char* const usage =
      " <slope|elevator> <integrator> <dt> <t_end> [rtol] [atol] [schur|klu]\n";
  if (argc == 2 && std::string(argv[1]) == "--help") {
    std::cout << "usage: " << argv[0] << usage;
    return 0;
  }
  if (argc < 5) {
    std::cerr << "error: expected at least 4 arguments\nusage: " << argv[0] << usage;
    return 2;
  }
  try {
    const std::string scene = argv[1];
    jelly::IntegratorOptions options;
    if (argc > 5) options.arkode.rtol = std::atof(argv[5]);
    if (argc > 6) options.arkode.atol = std::atof(argv[6]);
    if (argc > 7)
      options.arkode.linear_solver =
          jelly::value_of(jelly::arkode_linear_solvers(), argv[7], "linear_solver (argument 7)");
    const jelly::Model model = jelly::build_cube(jelly::CubeSpec{});
    jelly::SimulatorOptions sim_options;
    sim_options.dt = std::atof(argv[3]);
    sim_options.output_interval = 1.0 / 60;
    jelly::Simulator sim(model, jelly::rest_state(model), jelly::make_integrator(argv[2], options),
                         sim_options);
    if (scene == "elevator") {
      sim.add_terrain(std::make_unique<jelly::Elevator>());
    } else if (scene == "slope") {
      sim.add_terrain(std::make_unique<jelly::Plane>(jelly::Plane::slope(20)));
    } else {
      std::cerr << "error: scene must be slope or elevator\n";
      return 2;
    }
    const jelly::RunReport report = sim.run_until(std::atof(argv[4]));
    const jelly::Vec3 com = jelly::center_of_mass(model, sim.state());
    std::cout << scene << " " << argv[2] << " dt " << sim_options.dt << ": " << report.brief()
              << "\n  force evaluations " << report.force_evaluations << ", centre of mass "
              << com.transpose() << "\n ";
    for (const auto& [key, value] : report.statistics) std::cout << " " << key << " " << value;
    std::cout << "\n";
    return report.ok() ? 0 : 3;
  } catch (const jelly::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
