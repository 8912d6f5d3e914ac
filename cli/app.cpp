// jelly's commands on the command line: simulate scenes (run), describe recordings (info), fit
// coefficients to a recording (fit), list what a scene can name (list) and its options (fields),
// watch scenes and recordings (view), render videos (render), export surfaces for other tools
// (export), fill surfaces with tetrahedra (mesh).
#include <charconv>
#include <cstdio>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/version.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "output.hpp"

namespace {

// An option given with an empty value ("-o ''") is a mistake, never "not given".
const CLI::Validator kNonEmpty(
    [](std::string& value) {
      return value.empty() ? std::string("an empty value") : std::string();
    },
    "", "NONEMPTY");

// --threads: a count of threads, 0 for all cores (CLI11's NonNegativeNumber named the range of a
// double, a number of 310 digits).
const CLI::Validator kThreadCount(
    [](std::string& value) {
      int n = -1;
      const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), n);
      return error == std::errc() && end == value.data() + value.size() && n >= 0
                 ? std::string()
                 : value + " is invalid: an integer from 0 (all cores) to " +
                       std::to_string(std::numeric_limits<int>::max());
    },
    "", "THREADS");

constexpr const char* kFooter =
    "Exit codes: 0 ok, 2 bad input (scene, option or argument), 3 the run diverged or the solver "
    "failed (the output file keeps what was written), 1 any other failure.";

}  // namespace

namespace jelly::cli {

int run_jelly(int argc, char** argv) {
  prepare_output_library();
  CLI::App app{"jelly " JELLY_VERSION_STRING ": mass-spring soft-body simulation", "jelly"};
  app.footer(kFooter);
  app.require_subcommand(1);
  app.set_version_flag("--version", JELLY_VERSION_STRING);

  RunArgs run_args;
  CLI::App* run = app.add_subcommand("run", "Simulate a scene (JSON) and print a summary");
  run->add_option("scene", run_args.scene, "Scene file (JSON), e.g. scenes/seed_slope.json")
      ->required()
      ->check(kNonEmpty);
  run->add_option("-o,--output", run_args.output,
                  "Write the run to this HDF5 file (and an .xdmf beside it); an existing file "
                  "is an error unless --overwrite")
      ->check(kNonEmpty);
  run->add_flag("--overwrite", run_args.overwrite,
                "Replace an existing -o file (and its .xdmf), once the new recording is complete");
  run->add_option("--integrator", run_args.integrator,
                  "Integrator name (see `jelly list`); overrides integrator.name")
      ->check(kNonEmpty);
  run->add_option("--dt", run_args.dt, "Time step in s; overrides integrator.dt")
      ->type_name("H")
      ->check(kNonEmpty);
  run->add_option("--duration", run_args.duration, "Simulated time in s; overrides duration")
      ->type_name("T")
      ->check(kNonEmpty);
  run->add_option("--set", run_args.sets,
                  "Override a scene field, e.g. --set springs.structural.ks=2400 or "
                  "--set terrains[0].contact.restitution=0.5 (repeatable; the value is JSON, or "
                  "else a string)")
      ->type_name("PATH=VALUE")
      ->allow_extra_args(false)  // one PATH=VALUE per --set; a scene after it stays positional
      ->check(kNonEmpty);
  run->add_option("--restart", run_args.restart,
                  "Start from the last checkpoint of this HDF5 file (same scene)")
      ->check(kNonEmpty);
  run->add_flag("-q,--quiet", run_args.quiet, "No progress bar");
  run->add_flag("--strict", run_args.strict,
                "Exit 3 when steps missed the solver's own tolerance (status "
                "completed_with_warnings; without --strict a warning and exit 0)");
  run->add_option(
         "--threads", run_args.threads,
         "Threads for the force loop, the solves and contact (default: the scene's "
         "`threads`; 0 = all cores or one thread, chosen step by step from which runs faster; "
         "the results are the same for any number)")
      ->type_name("N")
      ->check(kThreadCount);

  std::string info_path;
  CLI::App* info = app.add_subcommand("info", "Describe an HDF5 file written by `jelly run -o`");
  info->add_option("file", info_path, "HDF5 file")->required()->check(kNonEmpty);

  XdmfArgs xdmf_args;
  CLI::App* xdmf = app.add_subcommand(
      "xdmf",
      "Write the XDMF sidecar (FILE.xdmf) that opens a recording in ParaView: for a killed run, "
      "or again for a recording made by an older jelly");
  xdmf->add_option("file", xdmf_args.recording, "HDF5 file")->required()->check(kNonEmpty);
  xdmf->add_flag("--overwrite", xdmf_args.overwrite,
                 "Replace an existing sidecar (and with --state, an existing state file)");
  xdmf->add_flag("--no-strain", xdmf_args.no_strain,
                 "No strain cell array (the largest part of what the sidecar adds to the file)");
  xdmf->add_flag(
      "--state", xdmf_args.state,
      "Also write FILE.paraview.py beside it: a ParaView state (File > Load State) that "
      "colours by speed over the range of all frames and frames the bodies over the run");

  FitArgs fit_args;
  CLI::App* fit = app.add_subcommand(
      "fit", "Fit spring and damper coefficients to a recording (HDF5 from `jelly run -o`)");
  fit->add_option("recording", fit_args.recording, "HDF5 file")->required()->check(kNonEmpty);
  fit->add_option("--free", fit_args.free,
                  "Coefficients to fit: ks,kd (all types together) or per type, e.g. "
                  "ks.structural,ks.shear,ks.bending,kd; each for every body or for one, "
                  "prefixed by its name: soft.ks,stiff.ks,kd")
      ->capture_default_str()
      ->check(kNonEmpty);
  fit->add_option("--window", fit_args.window,
                  "Multiple-shooting window in s, each replayed from a recorded state; 0 = one "
                  "window")
      ->capture_default_str();
  fit->add_option("--initial", fit_args.initial,
                  "Starting value, e.g. --initial ks=1400 (repeatable; default: the recording's "
                  "coefficients)")
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false)
      ->check(kNonEmpty);
  fit->add_option("--max-iterations", fit_args.max_iterations, "Ceres iterations at most")
      ->capture_default_str();
  fit->add_option("--write-scene", fit_args.write_scene,
                  "Write the recording's scene with the fitted coefficients to this JSON file; an "
                  "existing file is an error unless --overwrite")
      ->check(kNonEmpty);
  fit->add_flag("--overwrite", fit_args.overwrite, "Replace an existing --write-scene file");
  fit->add_flag("--no-covariance", fit_args.no_covariance,
                "No standard deviations: on the numeric path the restart-aware covariance "
                "replays every window twice per coordinate of its start state (6 x particles "
                "replays per window), most of the time on a large body");
  fit->add_option("--gradients", fit_args.gradients,
                  "auto: exact gradients from the adjoint of implicit_euler or projective_dynamics "
                  "when it supports the "
                  "recording, else numeric; adjoint: those or an error; numeric: central "
                  "differences of replays")
      ->capture_default_str();

  CLI::App* list = app.add_subcommand("list",
                                      "List the integrators, body and terrain kinds, contact "
                                      "models, forces and optional parts, one per line");

  std::string fields_format = "markdown";
  CLI::App* fields =
      app.add_subcommand("fields",
                         "Print every scene option's key, type, default, unit and constraint (the "
                         "field tables: the scene-key reference)");
  fields->add_option("--format", fields_format, "markdown or json")
      ->check(CLI::IsMember({"markdown", "json"}))
      ->capture_default_str();

  ViewArgs view_args;
  CLI::App* view = app.add_subcommand(
      "view", "Watch a scene live (JSON) or replay a recording (.h5) in a window");
  view->add_option("file", view_args.file, "Scene file (JSON) or recording (.h5)")->required();
  view->add_option("--integrator", view_args.integrator, "Integrator name (live)");
  view->add_option("--dt", view_args.dt, "Time step in s (live)")->type_name("H");
  view->add_option("--set", view_args.sets, "Override a scene field (live), as for `jelly run`")
      ->type_name("PATH=VALUE")
      ->allow_extra_args(false);
  view->add_option("--width", view_args.width, "Window width in pixels")->capture_default_str();
  view->add_option("--height", view_args.height, "Window height in pixels")->capture_default_str();
  view->add_option("--camera", view_args.camera,
                   "Camera: yaw,pitch,distance[,tx,ty,tz] (degrees, m); default: framed");
  view->add_option("--screenshot", view_args.screenshot,
                   "Write the window as PNG after --frames N frames and exit (live: each frame "
                   "is then one output interval of simulated time; replay: the next recorded "
                   "frame)")
      ->check(kNonEmpty);
  view->add_option("--frames", view_args.frames, "Exit after this many frames");
  view->add_option("--frame", view_args.frame, "Replay: the frame shown first");
  view->add_option("--speed", view_args.speed,
                   "Live: simulated seconds per wall second (0: as fast as possible)")
      ->capture_default_str();
  CLI::Option* view_samples =
      view->add_option("--samples", view_args.samples, "Multisampling (1 = none)")
          ->capture_default_str();
  view->add_flag("--fxaa", view_args.fxaa,
                 "Smooth edges by FXAA after drawing single-sampled, in place of multisampling "
                 "(cheaper on a software renderer)");
  view->add_flag("--paused", view_args.paused, "Start paused");
  view->add_flag("--hide-panel", view_args.hide_panel, "No panel (H toggles it)");
  view->add_flag("--particles", view_args.particles, "Show the particles");
  view->add_flag("--springs", view_args.springs, "Show the structural springs");
  view->add_flag("--overwrite", view_args.overwrite, "Replace an existing --screenshot file");
  view->add_flag("--stats", view_args.stats,
                 "Print frames per second, render and simulation times at exit");
  view->add_flag("--record", view_args.record,
                 "Live: record the run from the start, as the Record button (F9) does, to "
                 "jelly-<date>-<time>.h5 in --record-dir (replays and restarts like `jelly run "
                 "-o`; never replaces a file)");
  view->add_option("--record-dir", view_args.record_dir,
                   "Folder of the recordings (Record button, F9, --record) and screenshots "
                   "(F12)")
      ->capture_default_str()
      ->check(kNonEmpty);

  RenderArgs render_args;
  CLI::App* render = app.add_subcommand(
      "render", "Render a recording offscreen to a video (.mp4, .gif) or PNG frames");
  render->add_option("recording", render_args.recording, "HDF5 file from `jelly run -o`")
      ->required();
  render
      ->add_option("-o,--output", render_args.output,
                   "out.mp4, out.gif or a PNG pattern such as frames/%04d.png")
      ->required();
  render->add_option("--width", render_args.width, "Width in pixels")->capture_default_str();
  render->add_option("--height", render_args.height, "Height in pixels")->capture_default_str();
  render->add_option("--fps", render_args.fps,
                     "Video frames per simulated second (default: the recording's own rate)");
  render->add_option("--start", render_args.start, "First simulated time (s)");
  render->add_option("--end", render_args.end, "Last simulated time (s)");
  render->add_option("--camera", render_args.camera,
                     "Camera: yaw,pitch,distance[,tx,ty,tz] (degrees, m); default: as `jelly "
                     "view` frames the recording");
  CLI::Option* render_samples =
      render->add_option("--samples", render_args.samples, "Multisampling (1 = none)")
          ->capture_default_str();
  render->add_flag("--fxaa", render_args.fxaa,
                   "Smooth edges by FXAA after drawing single-sampled, in place of "
                   "multisampling (cheaper on a software renderer)");
  render->add_option("--crf", render_args.crf, "H.264 quality, lower is better")
      ->capture_default_str();
  render->add_flag("--particles", render_args.particles, "Show the particles");
  render->add_flag("--springs", render_args.springs, "Show the structural springs");
  render->add_flag("--no-shadows", render_args.no_shadows, "No shadows");
  render->add_flag("--overwrite", render_args.overwrite,
                   "Replace an existing output (an existing file is an error otherwise)");

  ExportArgs export_args;
  CLI::App* export_cmd = app.add_subcommand(
      "export",
      "Export a recording's surfaces and terrains for Blender, Houdini, ParaView, game engines: "
      "OBJ per frame, PC2, glTF");
  export_cmd->add_option("recording", export_args.recording, "HDF5 file from `jelly run -o`")
      ->required();
  export_cmd->add_option("--obj-sequence", export_args.obj_sequence,
                         "Folder for frame_0000.obj, frame_0001.obj, ... (with normals) and the "
                         "terrains beside them (terrain_<name>.obj, per frame when they move)");
  export_cmd->add_option("--pc2", export_args.pc2,
                         "PC2 point cache (the rest surface goes beside it as .obj)");
  export_cmd->add_option(
      "--gltf", export_args.gltf,
      "glTF 2.0 binary (.glb): the bodies with normals, colours and their "
      "animation as morph targets, the terrains and obstacles with their motion");
  export_cmd->add_flag("--overwrite", export_args.overwrite,
                       "Replace existing files (an existing file is an error otherwise)");

  MeshArgs mesh_args;
  CLI::App* mesh = app.add_subcommand(
      "mesh", "Fill a closed surface (.obj, .stl, .ply) with tetrahedra (Gmsh) for a tetmesh body");
  mesh->add_option("input", mesh_args.input, "Closed surface mesh: .obj, .stl or .ply")
      ->required()
      ->check(kNonEmpty);
  mesh->add_option("-o,--output", mesh_args.output, "Tetrahedral mesh to write (.msh, Gmsh 4.1)")
      ->required()
      ->check(kNonEmpty);
  mesh->add_option("--size", mesh_args.size,
                   "Element size in the surface's units: the surface is remeshed at this size "
                   "(default 0: keep its triangles)")
      ->type_name("H")
      ->capture_default_str();
  mesh->add_flag("--overwrite", mesh_args.overwrite, "Replace an existing -o file");

  // A first word that is no command ("jelly simulate") is named, with the commands there are
  // (CLI11 would say only that a subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    const std::string word = argv[1];
    std::string known;
    bool found = false;
    for (const CLI::App* command : app.get_subcommands({})) {
      found = found || command->get_name() == word;
      known += (known.empty() ? "" : ", ") + command->get_name();
    }
    if (!found) {
      std::fprintf(stderr, "error: unknown command '%s'; the commands are %s (jelly --help)\n",
                   word.c_str(), known.c_str());
      return kExitBadInput;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // The command given (checked above), else run's usage as the example.
    const std::string command = argc > 1 && argv[1][0] != '-' ? argv[1] : "run";
    std::fprintf(stderr, "error: %s\nRun 'jelly --help' or 'jelly %s --help' for usage.\n",
                 e.what(), command.c_str());
    return kExitBadInput;
  }

  try {
    if (run->parsed()) return run_command(run_args);
    if (info->parsed()) return info_command(info_path);
    if (xdmf->parsed()) return xdmf_command(xdmf_args);
    if (fit->parsed()) return fit_command(fit_args);
    if (list->parsed()) return list_command();
    if (fields->parsed()) return fields_command(fields_format);
    view_args.samples_given = view_samples->count() > 0;
    render_args.samples_given = render_samples->count() > 0;
    if (view->parsed()) return view_command(view_args);
    if (render->parsed()) return render_command(render_args);
    if (export_cmd->parsed()) return export_command(export_args);
    if (mesh->parsed()) return mesh_command(mesh_args);
  } catch (const jelly::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory\n");
    return kExitInternalError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitInternalError;
  }
  return kExitBadInput;  // unreachable: require_subcommand(1)
}

}  // namespace jelly::cli
