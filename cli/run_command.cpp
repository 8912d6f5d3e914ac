#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <jelly/io/scene.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "output.hpp"
#include "progress.hpp"
#include "summary.hpp"

namespace jelly::cli {

namespace {

// The overrides of a run: every --set in order, then the dedicated options, which win.
std::vector<std::string> overrides(const RunArgs& args) {
  std::vector<std::string> out = args.sets;
  if (!args.integrator.empty()) {
    out.push_back("integrator.name=" + nlohmann::json(args.integrator).dump());
  }
  if (!args.dt.empty()) out.push_back("integrator.dt=" + args.dt);
  if (!args.duration.empty()) out.push_back("duration=" + args.duration);
  return out;
}

}  // namespace

int run_command(const RunArgs& args) {
  const Scene scene = load_scene(args.scene, overrides(args));
  Simulator sim = make_simulator(scene);
  if (!args.restart.empty()) restore_from_file(sim, args.restart);

  std::unique_ptr<Observer> recorder;
  if (!args.output.empty()) {
    recorder = make_recorder(args.output, sim, scene);
    sim.add_observer(*recorder);
  }
  std::unique_ptr<ProgressBar> progress;
  if (!args.quiet && isatty(fileno(stderr))) {
    progress = std::make_unique<ProgressBar>(stderr, scene.duration);
    sim.add_observer(*progress);
  }

  const RunReport report = sim.run_until(scene.duration);
  print_summary(stdout, scene, sim, report, args.output);
  std::fflush(stdout);
  if (!report.ok()) {
    std::string message = "error: the run stopped early: " + report.brief();
    if (!args.output.empty()) message += " (" + args.output + " keeps what was written)";
    std::fprintf(stderr, "%s\n", message.c_str());
    return kExitRunFailed;
  }
  return kExitOk;
}

}  // namespace jelly::cli
