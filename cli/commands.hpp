#pragma once
// The subcommands of the jelly program. Each returns an exit code (exit_codes.hpp) and lets
// InputError escape for main() to print as "error: ...".
#include <string>
#include <vector>

namespace jelly::cli {

// The jelly program: parses argv (argv[0] the program's name), runs the command named and
// returns its exit code (exit_codes.hpp); every error is printed, none escapes.
int run_jelly(int argc, char** argv);

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
  bool overwrite = false;         // --overwrite: replace an existing -o file once complete
  int threads = -1;               // --threads: -1 = the scene's `threads`, 0 = all cores
  bool strict = false;  // --strict: a step that missed the solver's tolerance fails the run
};

// jelly run: load the scene with its overrides, simulate, record, summarise.
int run_command(const RunArgs& args);
// jelly info FILE.h5: what a recording holds.
int info_command(const std::string& path);

struct XdmfArgs {
  std::string recording;   // HDF5 file written by `jelly run -o` (or a killed run's)
  bool overwrite = false;  // --overwrite: replace an existing sidecar
  bool no_strain = false;  // --no-strain: no strain cell array (XdmfOptions::strain = false)
  bool state = false;      // --state: also a ParaView state beside it (write_paraview_state)
};
// jelly xdmf FILE.h5: (re)writes the recording's XDMF sidecar for ParaView.
int xdmf_command(const XdmfArgs& args);
struct FitArgs {
  std::string recording;             // HDF5 file written by `jelly run -o`
  std::string free = "ks,kd";        // --free: the coefficients to fit
  double window = 0.1;               // --window: multiple-shooting window (s), 0 = whole run
  std::vector<std::string> initial;  // --initial name=value: starting values
  int max_iterations = 50;           // --max-iterations
  std::string write_scene;           // --write-scene: the scene with the fitted values
  bool overwrite = false;            // --overwrite: replace an existing --write-scene file
  bool no_covariance = false;        // --no-covariance: estimates without standard deviations
  std::string gradients = "auto";    // --gradients: auto, adjoint or numeric
};

// jelly fit RECORDING.h5: the spring and damper coefficients that replay the recording best.
int fit_command(const FitArgs& args);
// jelly list: integrators, terrain kinds and contact models, one line each.
int list_command();
// jelly fields [--format markdown|json]: the field tables of the scene options.
int fields_command(const std::string& format);

struct ViewArgs {
  std::string file;  // a scene (JSON: live) or a recording (.h5: replay)
  std::string integrator, dt;
  std::vector<std::string> sets;
  int width = 1280, height = 720;
  std::string camera;
  std::string screenshot;
  int frames = -1;
  int frame = 0;  // replay: the frame shown first
  bool paused = false, hide_panel = false, particles = false, springs = false, stats = false;
  bool overwrite = false;  // replace an existing --screenshot file
  double speed = 1;
  int samples = 4;
  bool samples_given = false;  // --samples on the command line
  bool fxaa = false;
  bool record = false;           // live: record from the first frame (F9 / the Record button)
  std::string record_dir = ".";  // where recordings and F12 screenshots are written
};
// jelly view SCENE.json | FILE.h5: the live window or the replay.
int view_command(const ViewArgs& args);

struct RenderArgs {
  std::string recording;
  std::string output;
  int width = 1280, height = 720;
  double fps = 0;
  double start = -1, end = -1;
  std::string camera;
  int samples = 4;
  bool samples_given = false;  // --samples on the command line
  bool fxaa = false;
  int crf = 18;
  bool particles = false, springs = false, no_shadows = false;
  bool overwrite = false;  // replace an existing output (for PNG frames: frame 0)
};
// jelly render FILE.h5 -o out.mp4|out.gif|frames/%04d.png: offscreen video.
int render_command(const RenderArgs& args);

struct ExportArgs {
  std::string recording;
  std::string obj_sequence;  // folder of one OBJ per frame
  std::string pc2;           // PC2 file (+ the rest surface as .obj beside it)
  std::string gltf;          // glTF 2.0 binary (.glb), animated
  bool overwrite = false;    // replace existing files
};
// jelly export FILE.h5 --obj-sequence DIR | --pc2 out.pc2 | --gltf out.glb.
int export_command(const ExportArgs& args);

struct MeshArgs {
  std::string input;       // closed surface: .obj, .stl or .ply
  std::string output;      // -o: .msh
  double size = 0;         // --size: element size (m); 0 = keep the surface's triangles
  bool overwrite = false;  // --overwrite: replace an existing -o file
};
// jelly mesh IN.stl -o OUT.msh [--size h]: tetrahedralize a closed surface with Gmsh.
int mesh_command(const MeshArgs& args);

}  // namespace jelly::cli
