// jelly view, jelly render, jelly export: the viewer layer's commands. The window and the
// offscreen renderer are optional parts of the build (JELLY_HAVE_WINDOW, JELLY_HAVE_RENDER).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/viewer/detail/exports.hpp>
#ifdef JELLY_HAVE_RENDER
#include <jelly/viewer/render_video.hpp>
#include <jelly/viewer/video_writer.hpp>
#endif
#ifdef JELLY_HAVE_WINDOW
#include <jelly/viewer/window.hpp>
#endif

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

namespace {

// Commands never destroy a file they did not create unless told to (--overwrite), nor the
// recording they read.
void check_new_file(const std::string& flag, const std::string& path, bool overwrite,
                    const std::string& input) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return;
  // equivalent(): the same file also through symbolic and hard links.
  if (!input.empty() && std::filesystem::equivalent(path, input, error))
    throw InputError(flag + " " + path + " is the recording it is made from, " + input +
                     " (the same file): it would be overwritten; choose another name");
  if (!overwrite)
    throw InputError(flag + " " + path +
                     " exists (a file this command did not create): pass --overwrite to replace "
                     "it, or choose another name");
}

[[maybe_unused]] bool is_recording(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  return ext == ".h5" || ext == ".hdf5";
}

[[maybe_unused]] std::vector<std::string> overrides(const ViewArgs& args) {
  std::vector<std::string> out = args.sets;
  if (!args.integrator.empty())
    out.push_back("integrator.name=" + nlohmann::json(args.integrator).dump());
  if (!args.dt.empty()) out.push_back("integrator.dt=" + args.dt);
  return out;
}

}  // namespace

int view_command(const ViewArgs& args) {
#ifdef JELLY_HAVE_WINDOW
  require(args.width >= 16 && args.width <= 8192, "--width", args.width, "16 to 8192 pixels");
  require(args.height >= 16 && args.height <= 8192, "--height", args.height, "16 to 8192 pixels");
  require(args.frames >= -1, "--frames", args.frames, ">= 0 frames (-1: until closed)");
  require(args.speed >= 0, "--speed", args.speed, ">= 0 (0: as fast as possible)");
  require(args.samples >= 1 && args.samples <= 16, "--samples", args.samples, "1 to 16");
  require(!args.fxaa || !args.samples_given || args.samples == 1, "--samples", args.samples,
          "1 with --fxaa (FXAA replaces multisampling)");
  if (!args.screenshot.empty() && args.frames < 0)
    throw InputError("--screenshot", args.screenshot, "used with --frames N (the frame to save)");
  if (!args.screenshot.empty())
    check_new_file("--screenshot", args.screenshot, args.overwrite, args.file);
  viewer::ViewOptions options;
  options.width = args.width;
  options.height = args.height;
  options.camera = args.camera;
  if (!options.camera.empty()) viewer::Camera().parse(options.camera);  // checked before a window
  options.screenshot = args.screenshot;
  options.frames = args.frames;
  options.start_frame = args.frame;
  options.paused = args.paused;
  options.hide_panel = args.hide_panel;
  options.particles = args.particles;
  options.springs = args.springs;
  options.stats = args.stats;
  options.speed = args.speed;
  options.samples = args.fxaa ? 1 : args.samples;
  options.fxaa = args.fxaa;
  options.record = args.record;
  options.record_dir = args.record_dir;
  {
    std::error_code error;
    if (!std::filesystem::is_directory(args.record_dir, error))
      throw InputError("--record-dir", args.record_dir, "an existing folder");
  }
  try {
    std::unique_ptr<viewer::ViewerWindow> window;
    if (is_recording(args.file)) {
      if (!args.sets.empty() || !args.integrator.empty() || !args.dt.empty())
        throw InputError("--set/--integrator/--dt", args.file,
                         "options of a live scene, not of a recording");
      if (args.record)
        throw InputError("--record", args.file,
                         "an option of a live scene (a replay is a recording already)");
      window = viewer::ViewerWindow::replay(args.file, options);
    } else {
      const Scene scene = load_scene(args.file, overrides(args));
      window = viewer::ViewerWindow::live(scene, args.file, options);
    }
    return window->run();
  } catch (const viewer::DisplayUnavailable& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  }
#else
  (void)args;
  std::fprintf(stderr,
               "error: this jelly was built without the viewer window (GLFW, Dear ImGui or "
               "OpenGL were not found when it was configured: apt-get install libglfw3-dev "
               "libimgui-dev libegl-dev libstb-dev, then rebuild)\n");
  return kExitBadInput;
#endif
}

int render_command(const RenderArgs& args) {
#ifdef JELLY_HAVE_RENDER
  viewer::RenderVideoOptions options;
  options.width = args.width;
  options.height = args.height;
  options.fps = args.fps;
  options.start = args.start;
  options.end = args.end;
  options.camera = args.camera;
  options.samples = args.fxaa ? 1 : args.samples;
  options.fxaa = args.fxaa;
  options.crf = args.crf;
  options.particles = args.particles;
  options.springs = args.springs;
  options.shadows = !args.no_shadows;
  require(args.fps >= 0, "--fps", args.fps, "> 0 frames per second (0: the recording's rate)");
  require(args.crf >= 0 && args.crf <= 51, "--crf", args.crf, "0 to 51");
  require(!args.fxaa || !args.samples_given || args.samples == 1, "--samples", args.samples,
          "1 with --fxaa (FXAA replaces multisampling)");
  if (viewer::video_format(args.output, "-o") == viewer::VideoFormat::kPngSequence) {
    std::vector<char> first(args.output.size() + 32);
    std::snprintf(first.data(), first.size(), args.output.c_str(), 0);
    check_new_file("-o", first.data(), args.overwrite, args.recording);
  } else {
    check_new_file("-o", args.output, args.overwrite, args.recording);
  }
  const viewer::RenderVideoReport r = viewer::render_video(args.recording, args.output, options);
  std::printf(
      "rendered %d frames of %dx%d to %s in %.2f s (%.1f ms per frame: drawing %.1f, "
      "encoding %.1f)\nrenderer: %s\n",
      r.frames, args.width, args.height, args.output.c_str(), r.seconds,
      1e3 * r.seconds / std::max(1, r.frames), 1e3 * r.render_seconds / std::max(1, r.frames),
      1e3 * r.encode_seconds / std::max(1, r.frames), r.renderer.c_str());
  return kExitOk;
#else
  (void)args;
  std::fprintf(stderr,
               "error: this jelly was built without offscreen rendering (OpenGL, EGL or stb were "
               "not found when it was configured: apt-get install libopengl-dev libegl-dev "
               "libstb-dev, then rebuild)\n");
  return kExitBadInput;
#endif
}

int export_command(const ExportArgs& args) {
  if (args.obj_sequence.empty() && args.pc2.empty() && args.gltf.empty())
    throw InputError("jelly export", args.recording,
                     "one or more of --obj-sequence DIR, --pc2 FILE.pc2, --gltf FILE.glb");
  if (!args.gltf.empty()) {
    if (std::filesystem::path(args.gltf).extension() != ".glb")
      throw InputError("--gltf", args.gltf, "a path ending in .glb (binary glTF 2.0)");
    std::error_code error;
    if (std::filesystem::is_directory(args.gltf, error))
      throw InputError("--gltf", args.gltf, "a file path (it is a folder)");
    if (!viewer::gltf_available()) viewer::export_gltf(Recording{}, args.gltf);  // says why
    check_new_file("--gltf", args.gltf, args.overwrite, args.recording);
  }
  if (!args.obj_sequence.empty()) {
    check_new_file("--obj-sequence", args.obj_sequence + "/frame_0000.obj", args.overwrite,
                   args.recording);
    // Every frame of an earlier sequence there: --overwrite replaces them all (its frames past
    // the new sequence's last are removed), and none may be the recording.
    for (const std::string& frame : viewer::obj_sequence_files(args.obj_sequence))
      check_new_file("--obj-sequence", frame, args.overwrite, args.recording);
  }
  if (!args.pc2.empty()) {
    check_new_file("--pc2", args.pc2, args.overwrite, args.recording);
    check_new_file("--pc2 (its rest surface)",
                   std::filesystem::path(args.pc2).replace_extension(".obj").string(),
                   args.overwrite, args.recording);
  }
  const Recording recording = read_recording(args.recording);
  if (!args.obj_sequence.empty()) {
    const int files = viewer::export_obj_sequence(recording, args.obj_sequence, args.overwrite);
    std::printf("wrote %d OBJ files to %s (frame_0000.obj ...)\n", files,
                args.obj_sequence.c_str());
  }
  if (!args.pc2.empty()) {
    const std::string rest = viewer::export_pc2(recording, args.pc2);
    std::printf("wrote %s (%d samples) and its rest surface %s\n", args.pc2.c_str(),
                recording.frames(), rest.c_str());
  }
  if (!args.gltf.empty()) {
    viewer::export_gltf(recording, args.gltf);
    std::printf("wrote %s (%d frames)\n", args.gltf.c_str(), recording.frames());
  }
  return kExitOk;
}

}  // namespace jelly::cli
