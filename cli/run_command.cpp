#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/run_limits.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>

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

bool exists(const std::string& path, struct stat* info) { return stat(path.c_str(), info) == 0; }

// Whether a and b name the same existing file (also through links or other spellings).
bool same_file(const std::string& a, const std::string& b) {
  struct stat x {
  }, y{};
  return exists(a, &x) && exists(b, &y) && x.st_dev == y.st_dev && x.st_ino == y.st_ino;
}

// Every "file" field of the scene (the mesh and tet mesh files of bodies and obstacles, of any
// kind), as the scene resolved them (absolute, or relative to the current directory).
void collect_files(const nlohmann::json& value, std::vector<std::string>& files) {
  if (value.is_object()) {
    for (auto it = value.begin(); it != value.end(); ++it) {
      if (it.key() == "file" && it.value().is_string()) {
        files.push_back(it.value().get<std::string>());
      } else {
        collect_files(it.value(), files);
      }
    }
  } else if (value.is_array()) {
    for (const nlohmann::json& item : value) collect_files(item, files);
  }
}

// A run never destroys a file it did not create unless told to (--overwrite), and never the
// files it reads from: checked before anything is computed.
void check_output_paths(const RunArgs& args, const Scene& scene) {
  const std::string& out = args.output;
  const std::string sidecar = sidecar_path_for(out);
  const std::string o = "-o " + out;
  if (sidecar == out) {
    throw InputError(o +
                     ": the recording is an HDF5 file and its XDMF sidecar is written beside it "
                     "under the same name with .xdmf: name the recording .h5 (e.g. -o " +
                     out.substr(0, out.size() - 5) + ".h5)");
  }
  if (same_file(out, args.scene)) {
    throw InputError(o + " is the scene file: the recording would overwrite it");
  }
  if (same_file(sidecar, args.scene)) {
    throw InputError(o + ": its XDMF sidecar " + sidecar +
                     " is the scene file: the run would overwrite it");
  }
  std::vector<std::string> files;
  collect_files(nlohmann::json::parse(scene_to_json(scene)), files);
  for (const std::string& file : files) {
    for (const std::string& path : {out, sidecar}) {
      if (same_file(path, file)) {
        throw InputError(o + (path == out ? "" : ": its XDMF sidecar " + path) +
                         " is the mesh file " + file +
                         " that the scene reads (the same file): it would be overwritten");
      }
    }
  }
  if (!args.restart.empty() && same_file(out, args.restart)) {
    throw InputError(o +
                     " is the --restart file: the continuation would replace the frames it "
                     "holds; write it to another file");
  }
  struct stat info {};
  for (const std::string& path : {out, sidecar}) {
    if (!exists(path, &info)) continue;
    const std::string what = path == out ? o : o + ": its XDMF sidecar " + path;
    if (S_ISDIR(info.st_mode)) throw InputError(what + " is a directory");
    if (!S_ISREG(info.st_mode)) throw InputError(what + " exists and is not a file");
    if (!args.overwrite) {
      throw InputError(what +
                       " exists (a file this run did not create): pass --overwrite to replace it "
                       "(only once the new recording is complete), or choose another name");
    }
  }
}

// Forwards frames to the recorder; a failure to write (a full disk) stops the run with
// RecordingFailed instead of leaving it to the simulator's caller as a raw library error.
struct RecordingFailed {
  std::string message;
};

class GuardedRecorder final : public Observer {
 public:
  explicit GuardedRecorder(std::unique_ptr<Observer> recorder) : recorder_(std::move(recorder)) {}
  void on_frame(const Simulator& sim) override {
    guard([&] { recorder_->on_frame(sim); });
  }
  void on_finish(const Simulator& sim, const RunReport& report) override {
    guard([&] { recorder_->on_finish(sim, report); });
  }

 private:
  template <typename F>
  void guard(F&& f) {
    try {
      f();
    } catch (const std::exception& e) {
      throw RecordingFailed{e.what()};
    }
  }
  std::unique_ptr<Observer> recorder_;
};

}  // namespace

int run_command(const RunArgs& args) {
  const Scene scene = load_scene(args.scene, overrides(args));
  std::shared_ptr<const Checkpoint> checkpoint;
  if (!args.restart.empty()) checkpoint = read_restart(args.restart, scene);
  if (!args.output.empty()) check_output_paths(args, scene);

  RunLimits limits;
  if (!args.output.empty()) limits.disk_bytes = free_disk_bytes(args.output);
  check_run_limits(scene, checkpoint ? checkpoint_time(*checkpoint) : 0, limits, args.output,
                   args.restart);

  Simulator sim = make_simulator(scene);
  if (args.threads >= 0) sim.set_threads(args.threads);
  if (checkpoint) restore_from(sim, *checkpoint, args.restart);
  for (const std::string& warning : seed_step_warnings(sim.model(), sim.state(), sim.terrains(),
                                                       sim.options().dt, scene.duration))
    std::fprintf(stderr, "warning: %s\n", warning.c_str());

  std::unique_ptr<Observer> recorder;
  struct stat output_info {};
  const bool replacing = !args.output.empty() && exists(args.output, &output_info);
  if (!args.output.empty()) {
    recorder =
        std::make_unique<GuardedRecorder>(make_recorder(args.output, sim, scene, args.overwrite));
    sim.add_observer(*recorder);
  }
  std::unique_ptr<ProgressBar> progress;
  if (!args.quiet && isatty(fileno(stderr))) {
    progress = std::make_unique<ProgressBar>(stderr, scene.duration);
    sim.add_observer(*progress);
  }

  const long steps_before = sim.total_steps();
  const long evaluations_before = sim.force_evaluations();
  const auto start = std::chrono::steady_clock::now();
  RunReport report;
  try {
    report = sim.run_until(scene.duration);
  } catch (const RecordingFailed& failure) {
    // What the run did up to here, then why it stopped.
    report.t = sim.state().t;
    report.steps = sim.total_steps() - steps_before;
    report.force_evaluations = sim.force_evaluations() - evaluations_before;
    report.statistics = sim.integrator().statistics();
    report.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (progress) progress->on_finish(sim, report);
    char headline[160];
    std::snprintf(headline, sizeof headline,
                  "stopped at t = %g s after %ld steps: the recording failed", report.t,
                  report.steps);
    print_summary(stdout, scene, sim, report, args.output, headline);
    std::fflush(stdout);
    recorder.reset();  // closes the file (and drops an unfinished replacement)
    const bool replaced_nothing = args.overwrite && replacing;
    std::fprintf(stderr, "error: writing %s failed: %s (%s)\n", args.output.c_str(),
                 failure.message.c_str(),
                 replaced_nothing ? "the existing file of that name is left as it was"
                                  : salvage_note(args.output).c_str());
    return kExitInternalError;
  }
  print_summary(stdout, scene, sim, report, args.output);
  std::fflush(stdout);
  if (!report.ok()) {
    std::string message = "error: the run stopped early: " + report.brief();
    if (!args.output.empty()) message += " (" + args.output + " keeps what was written)";
    std::fprintf(stderr, "%s\n", message.c_str());
    return kExitRunFailed;
  }
  if (report.has_warnings()) {
    if (args.strict) {
      const bool crushed = report.reason.find(" is crushed: ") != std::string::npos;
      std::fprintf(stderr, "error: the run %s (--strict): %s\n",
                   crushed ? "ended with warnings" : "missed its solver's tolerance",
                   report.reason.c_str());
      return kExitRunFailed;
    }
    std::fprintf(stderr, "warning: %s (--strict makes this an error)\n", report.reason.c_str());
  }
  return kExitOk;
}

}  // namespace jelly::cli
