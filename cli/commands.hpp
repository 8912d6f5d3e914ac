#pragma once
// The subcommands of the jelly program. Each returns an exit code (exit_codes.hpp) and lets
// InputError escape for main() to print as "error: ...".
#include <string>
#include <vector>

namespace jelly::cli {

struct RunArgs {
  std::string scene;       // scene file (JSON)
  std::string output;      // -o: HDF5 file, empty = none
  std::string integrator;  // --integrator: overrides integrator.name
  // --dt and --duration: JSON values for integrator.dt and duration, so that a bad value is
  // reported by the scene validation with its JSON path.
  std::string dt;
  std::string duration;
  std::vector<std::string> sets;  // --set path=value, in order
  std::string restart;            // --restart: checkpoint file
  bool quiet = false;             // --quiet: no progress bar
};

// jelly run: load the scene with its overrides, simulate, record, summarise.
int run_command(const RunArgs& args);
// jelly info FILE.h5: what a recording holds.
int info_command(const std::string& path);
struct FitArgs {
  std::string recording;             // HDF5 file written by `jelly run -o`
  std::string free = "ks,kd";        // --free: the coefficients to fit
  double window = 0.1;               // --window: multiple-shooting window (s), 0 = whole run
  std::vector<std::string> initial;  // --initial name=value: starting values
  int max_iterations = 50;           // --max-iterations
  std::string write_scene;           // --write-scene: the scene with the fitted values
};

// jelly fit RECORDING.h5: the spring and damper coefficients that replay the recording best.
int fit_command(const FitArgs& args);
// jelly list: integrators, terrain kinds and contact models, one line each.
int list_command();

}  // namespace jelly::cli
