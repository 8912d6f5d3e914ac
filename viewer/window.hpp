#pragma once
// `jelly view`: a window (GLFW, OpenGL 3.3 core, Dear ImGui) that simulates a scene live
// (LiveSimulation on its own thread) or replays a recording with a time slider, drawn by the
// shared Renderer through a RenderTarget. Mouse: left drag on a body drags the particle under
// the cursor with a spring (live), elsewhere orbits; right or middle drag (or shift + left) pans;
// the wheel zooms. Keys: space play/pause, S step, R reset, H hide the panel, P particles,
// L springs, F9 record on/off (live), F12 screenshot, Esc close.
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <jelly/io/scene.hpp>
#include <jelly/viewer/camera.hpp>
#include <jelly/viewer/live_simulation.hpp>

namespace jelly::viewer {

struct ViewOptions {
  int width = 1280, height = 720;
  std::string camera;      // "yaw,pitch,distance[,tx,ty,tz]"; empty: framed automatically
  std::string screenshot;  // PNG of the window after `frames` frames, then exit
  int frames = -1;         // frames to show before exiting; -1: until the window is closed
  bool hide_panel = false;
  bool paused = false;  // live: start paused
  int start_frame = 0;  // replay: the frame shown first
  int samples = 4;      // multisampling
  bool fxaa = false;    // FXAA after single-sampled drawing, in place of multisampling
  double speed = 1;     // simulated seconds per wall second; 0 = as fast as possible
  bool particles = false, springs = false;
  // Live: every shown frame advances the simulation by exactly one output interval on the
  // window's thread (deterministic screenshots); set when a screenshot is asked for.
  bool lockstep = false;
  bool stats = false;  // print frame, render and simulation timings at exit
  // Live: record from the first frame (as F9 or the Record button do later). Recordings and
  // F12 screenshots go to record_dir, named jelly-<date>-<time>[-k].{h5,png}; none replaces a
  // file.
  bool record = false;
  std::string record_dir = ".";
};

// No display, or no OpenGL 3.3 context on it: the CLI says so and exits 2.
class DisplayUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A rectangle of the window (x right, y down), in window coordinates.
struct PanelRect {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool overlaps(const PanelRect& o) const {
    return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1;
  }
};

class ViewerWindow {
 public:
  // Throw DisplayUnavailable without a display, InputError for a bad scene, file or option.
  static std::unique_ptr<ViewerWindow> live(const Scene& scene, const std::string& scene_path,
                                            const ViewOptions& options);
  static std::unique_ptr<ViewerWindow> replay(const std::string& h5_path,
                                              const ViewOptions& options);
  ~ViewerWindow();

  // Shows frames until the window is closed (or options.frames were shown); returns the exit
  // code, 0.
  int run();
  // One frame: events, simulation or replay, drawing, the panel, swap. False once the window
  // is to close.
  bool frame();

  // Mouse input in window coordinates, as the GLFW callbacks deliver it (tests call these to
  // exercise the same code).
  void mouse_button(int button, bool press, double x, double y, int mods = 0);
  void cursor(double x, double y);
  void scroll(double dy);
  // A key press (a GLFW key code), as the key callback delivers it.
  void key(int glfw_key);
  // What the close button does.
  void request_close();

  Camera& camera();
  int width() const;  // of the drawing, in pixels
  int height() const;
  // The particle positions drawn by the last frame.
  const VecX& positions() const;
  // The particle being dragged, or -1.
  int dragged_particle() const;
  // Null when replaying.
  LiveSimulation* simulation();
  // The last frame's panel (empty when hidden) and divergence banner (none when running), in
  // window coordinates; and the labels of panel items its right edge cut off.
  PanelRect panel_rect() const;
  std::optional<PanelRect> banner_rect() const;
  const std::vector<std::string>& clipped_panel_items() const;
  // Writes the last drawn frame (with the panel, unless hidden) as PNG.
  void save_screenshot(const std::string& path);
  // Live: starts or stops recording (the Record button, F9); the file of the current or last
  // recording, and of the last F12 screenshot (empty: none yet).
  void toggle_recording();
  std::string recording_path() const;
  std::string last_screenshot() const;
  // A message about the last recording or screenshot that failed, empty when none did.
  std::string recording_error() const;

 private:
  struct Impl;
  explicit ViewerWindow(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace jelly::viewer
