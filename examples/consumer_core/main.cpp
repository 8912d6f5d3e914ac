// The seed cube on the seed slope, built in code with jelly's core alone, run for DURATION
// seconds of implicit Euler at 1/60 s; prints the components and integrators this program has
// and the centre of mass:
//   consumer_core [DURATION]
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <jelly/core/components.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/core/model.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/plane.hpp>

int main(int argc, char** argv) {
  try {
    const double duration = argc > 1 ? std::stod(argv[1]) : 1.0;
    std::string names;
    for (const jelly::ComponentInfo& c : jelly::components()) names += " " + std::string(c.name);
    std::printf("components:%s\n", names.c_str());
    names.clear();
    for (const std::string& name : jelly::integrator_names()) names += " " + name;
    std::printf("integrators:%s\n", names.c_str());

    jelly::Model model = jelly::build_cube(jelly::CubeSpec{});
    jelly::State state = jelly::initial_state(model);
    jelly::SimulatorOptions options;
    options.dt = 1.0 / 60;
    jelly::Simulator sim(std::move(model), std::move(state),
                         jelly::make_integrator("implicit_euler"), options);
    const double angle = 20 * std::acos(-1.0) / 180;  // the seed slope: 20 degrees about z
    sim.add_terrain(std::make_unique<jelly::Plane>(
        Eigen::Vector3d::Zero(), Eigen::Vector3d(std::sin(angle), std::cos(angle), 0)));
    const jelly::RunReport report = sim.run_until(duration);
    const Eigen::Vector3d com = jelly::center_of_mass(sim.model(), sim.state());
    std::printf("%s\ncentre of mass: %.4f %.4f %.4f\n", report.brief().c_str(), com.x(), com.y(),
                com.z());
    return report.ok() ? 0 : 3;
  } catch (const jelly::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
