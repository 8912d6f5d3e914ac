#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/fit/detail/recording_trajectory.hpp>
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

// --write-scene: checked before the fit (which takes a while) so that a file it would destroy
// (the recording, or any existing file without --overwrite) or cannot write is an error at once.
void check_write_scene(const FitArgs& args) {
  const std::string& path = args.write_scene;
  struct stat target {
  }, recording{};
  if (stat(path.c_str(), &target) == 0) {
    if (stat(args.recording.c_str(), &recording) == 0 && target.st_dev == recording.st_dev &&
        target.st_ino == recording.st_ino) {
      throw InputError("--write-scene " + path + " is the recording " + args.recording +
                       " (the same file): it would be overwritten; choose another name");
    }
    if (!S_ISREG(target.st_mode)) {
      throw InputError("--write-scene " + path + " exists and is not a file");
    }
    if (!args.overwrite) {
      throw InputError("--write-scene " + path +
                       " exists (a file this run did not create): pass --overwrite to replace "
                       "it, or choose another name");
    }
    if (access(path.c_str(), W_OK) != 0) {
      throw InputError("--write-scene " + path + ": " + std::strerror(errno));
    }
    return;
  }
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) throw InputError("--write-scene " + path + ": " + std::strerror(errno));
  close(fd);
  std::remove(path.c_str());
}

}  // namespace

int fit_command(const FitArgs& args) {
  if (!args.write_scene.empty()) check_write_scene(args);
  const Recording recording = read_recording(args.recording);
  const Trajectory trajectory = trajectory_from_recording(recording);
  FitOptions options;
  options.free = parse_free_parameters(args.free);
  options.window = args.window;
  options.max_iterations = args.max_iterations;
  options.compute_covariance = !args.no_covariance;
  options.gradients = fit_gradients_from_name(args.gradients, "--gradients");
  for (const std::string& assignment : args.initial) {
    const auto [name, value] = parse_initial(assignment);
    bool known = false;
    for (const FitParameter& p : options.free) known = known || p.name() == name;
    require(known, "--initial", assignment, "a name from --free (" + args.free + ")");
    options.initial[name] = value;
  }
  const FitResult result = fit_recording(trajectory, options);
  std::fputs(result.report().c_str(), stdout);
  // Ceres reports a cost of -1 when the residuals could not be evaluated at all (every replay
  // from the starting values failed): nothing was fitted, so no scene is written.
  const auto evaluated = [](Real cost) { return std::isfinite(cost) && cost >= 0; };
  if (!evaluated(result.initial_cost) || !evaluated(result.final_cost)) {
    std::fprintf(stderr,
                 "error: the fit's residuals could not be evaluated (initial cost %g, final cost "
                 "%g: %s); nothing was fitted%s\n",
                 result.initial_cost, result.final_cost, result.termination.c_str(),
                 args.write_scene.empty() ? "" : " and no scene was written");
    return kExitRunFailed;
  }
  if (!args.write_scene.empty()) {
    detail::replace_file(args.write_scene, scene_to_json(fitted_scene(recording, result)) + "\n");
    std::printf("fitted scene written to %s\n", args.write_scene.c_str());
  }
  return kExitOk;
}

}  // namespace jelly::cli
