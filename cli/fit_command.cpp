#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <jelly/core/errors.hpp>
#include <jelly/fit/recording_trajectory.hpp>
#include <jelly/fit/spring_fit.hpp>
#include <jelly/io/recording.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

namespace {

// "ks=1400" -> {"ks", 1400}; the name is checked by the fit against the free parameters.
std::pair<std::string, Real> parse_initial(const std::string& assignment) {
  const auto eq = assignment.find('=');
  char* end = nullptr;
  const std::string value = eq == std::string::npos ? "" : assignment.substr(eq + 1);
  const double number = std::strtod(value.c_str(), &end);
  require(eq != std::string::npos && eq > 0 && !value.empty() && *end == '\0' && number > 0,
          "--initial", assignment, "NAME=VALUE with a free parameter's name and a value > 0");
  return {assignment.substr(0, eq), number};
}

}  // namespace

int fit_command(const FitArgs& args) {
  const Recording recording = read_recording(args.recording);
  const Trajectory trajectory = trajectory_from_recording(recording);
  FitOptions options;
  options.free = parse_free_parameters(args.free);
  options.window = args.window;
  options.max_iterations = args.max_iterations;
  for (const std::string& assignment : args.initial) {
    const auto [name, value] = parse_initial(assignment);
    bool known = false;
    for (const FitParameter& p : options.free) known = known || p.name() == name;
    require(known, "--initial", assignment, "a name from --free (" + args.free + ")");
    options.initial[name] = value;
  }
  const FitResult result = fit_recording(trajectory, options);
  std::fputs(result.report().c_str(), stdout);
  if (!args.write_scene.empty()) {
    std::ofstream out(args.write_scene);
    require(static_cast<bool>(out), "--write-scene", args.write_scene,
            "a file that can be written");
    out << scene_to_json(fitted_scene(recording, result)) << "\n";
    require(static_cast<bool>(out), "--write-scene", args.write_scene,
            "a file that can be written");
    std::printf("fitted scene written to %s\n", args.write_scene.c_str());
  }
  return kExitOk;
}

}  // namespace jelly::cli
