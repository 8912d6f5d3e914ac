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
// jelly list: integrators, terrain kinds and contact models, one line each.
int list_command();

}  // namespace jelly::cli
