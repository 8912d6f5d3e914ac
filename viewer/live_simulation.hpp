#pragma once
// The simulation behind `jelly view SCENE.json`: on its own thread, paced to real time (or a
// multiple of it), taking the panel's commands (play, pause, step, reset, coefficient changes,
// the mouse drag) between steps and publishing frames through a triple buffer, so that neither
// side waits on the other longer than an index swap; or, in lockstep, advanced by the caller
// (screenshots and tests: deterministic frames).
#include <array>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <jelly/core/force.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/run_report.hpp>

namespace jelly {
class H5Recorder;
}

namespace jelly::viewer {

// What the panel edits; a change is applied to the running simulator through its live setters
// (the run goes on from the current state with the new integrator, step or coefficients; pins,
// forces and everything else are kept).
struct LiveSettings {
  using BodySprings = std::array<SpringCoefficients, kSpringTypeCount>;
  std::string integrator;
  Real dt = 0.001;
  std::vector<BodySprings> springs;  // per body of the scene, in its order
  Vec3 gravity{0, -9.8, 0};
  std::vector<ContactParams> contacts;  // per terrain of the scene

  static LiveSettings of(const Scene& scene);
  // The scene with these settings.
  Scene applied_to(Scene scene) const;
};

// One published state with what the panel shows about it.
struct LiveFrame {
  unsigned long generation = 0;  // the scene it belongs to (load() starts a new one)
  Real t = 0;
  long steps = 0;
  VecX x;
  Real kinetic = 0, elastic = 0, gravitational = 0;
  Vec3 center_of_mass = Vec3::Zero();
  double steps_per_second = 0;        // measured over the last half second of wall time
  double sim_seconds_per_second = 0;  // simulated seconds per wall second, same window
  double step_milliseconds = 0;       // wall time of one step, averaged
  double step_cpu_milliseconds = 0;   // CPU time of the simulation thread per step, averaged
  bool playing = false;
  RunStatus status = RunStatus::kCompleted;  // kDiverged or kSolverFailed stop the simulation
  std::string message;                       // the divergence guard's or solver's reason
  // The recording of the live run (start_recording): its file while it records, else the last
  // one finished; its frames; why it could not be made or written.
  bool recording = false;
  std::string recording_path;
  long recorded_frames = 0;
  std::string recording_error;
  long recording_request = 0;  // the last start_recording() or stop_recording() taken
};

class LiveSimulation {
 public:
  // threaded: steps on its own thread while playing, pausing when the time reaches the scene's
  // duration (Play then goes on past it); otherwise only advance_to() steps.
  // on_publish (may be empty) is called on the simulating thread after each published frame
  // (the window wakes up with it). Throws InputError for an invalid scene.
  LiveSimulation(Scene scene, bool threaded, std::function<void()> on_publish = {});
  ~LiveSimulation();
  LiveSimulation(const LiveSimulation&) = delete;
  LiveSimulation& operator=(const LiveSimulation&) = delete;

  // Commands, applied by the simulation thread before its next step.
  void set_playing(bool playing);
  void step_once();  // pauses, then one step
  void reset();      // the scene's initial state with the current settings
  // A new scene (a new generation); throws InputError for an invalid one.
  void load(Scene scene);
  // Simulated seconds per wall second; 0 = as fast as possible.
  void set_speed(double speed);
  // Throws InputError for an unknown integrator or a bad value (checked on this thread).
  void apply(const LiveSettings& settings);
  // The mouse drag (an anchor spring), or none.
  void set_drag(std::optional<AnchorSpring> drag);

  // Records the run from its current state on to `path`, as `jelly run -o` records (io/
  // h5_recorder.hpp, with its XDMF sidecar): a frame now and one every output interval of
  // simulated time, drags and panel changes included; the scene as it goes on (after panel
  // changes) is stored at the end, so the file replays and restarts like any recording.
  // Throws InputError when `path` (or its sidecar) exists: a recording never replaces a file.
  // A reset, a new scene, stop_recording() or the end of the simulation finishes the file; a
  // failure to create or write it shows in LiveFrame::recording_error.
  void start_recording(const std::string& path);
  void stop_recording();
  // UI side: whether a recording was asked for and not stopped since.
  bool recording() const { return recording_; }

  // Lockstep (not threaded): steps until the time reaches t_end (within dt / 2, as
  // Simulator::run_until) unless stopped, then publishes.
  void advance_to(Real t_end);

  // Takes the newest published frame, if there is one; front() is then that frame. Only the
  // consuming (UI) thread calls these.
  bool refresh();
  const LiveFrame& front() const { return frames_[front_]; }

  // The scene and settings as last loaded or applied (UI thread).
  const Scene& scene() const { return scene_; }
  const LiveSettings& settings() const { return settings_; }
  // The simulator (lockstep only: a threaded simulation owns it on its own thread).
  const Simulator& simulator() const { return *sim_; }
  unsigned long generation() const { return generation_; }
  bool playing() const { return playing_; }

 private:
  struct Commands {
    std::optional<bool> playing;
    bool step = false, reset = false;
    std::optional<Scene> scene;  // with the settings applied
    std::optional<LiveSettings> settings;
    bool drag_changed = false;
    std::optional<AnchorSpring> drag;
    std::optional<double> speed;
    std::optional<std::string> record_to;  // start recording to this path
    bool stop_recording = false;
    long recording_request = 0;  // 0: no recording command
  };
  void loop();
  // Applies pending commands on the simulation side; true if anything changed.
  bool take_commands();
  void rebuild(const Scene& scene, bool keep_state);
  // Applies what differs between the simulator's settings and `settings` through the
  // simulator's setters.
  void apply_live(const LiveSettings& settings);
  // One step with the divergence check; false when the simulation stopped.
  bool step();
  void publish();
  // Simulation side: the recorder's frame when one is due, and the end of the recording.
  void record_if_due();
  void finish_recording();

  // UI side.
  Scene scene_;
  LiveSettings settings_;
  unsigned long generation_ = 1;
  bool playing_ = false;
  bool recording_ = false;
  long recording_requests_ = 0;

  // Shared, under mutex_.
  std::mutex mutex_;
  std::condition_variable wake_;
  Commands pending_;
  bool quit_ = false;
  std::array<LiveFrame, 3> frames_;
  int front_ = 0, middle_ = 1, back_ = 2;
  bool fresh_ = false;

  // Simulation side.
  std::unique_ptr<Simulator> sim_;
  Scene sim_scene_;
  LiveSettings sim_settings_;  // of sim_scene_
  unsigned long sim_generation_ = 1;
  long steps_ = 0;
  bool sim_playing_ = false;
  bool stopped_ = false;
  RunStatus status_ = RunStatus::kCompleted;
  std::string message_;
  double speed_ = 1;
  std::optional<AnchorSpring> drag_;
  std::unique_ptr<H5Recorder> recorder_;
  Real record_next_ = 0;  // simulated time of the next recorded frame
  std::string record_path_, record_error_;
  long record_frames_ = 0;
  long record_request_ = 0;
  bool record_scene_changed_ = false;  // the panel changed the run's settings while recording
  // Rate measurement: steps and simulated time at the start of the window.
  double rate_wall_ = 0;
  long rate_steps_ = 0;
  Real rate_t_ = 0;
  double steps_per_second_ = 0, sim_rate_ = 0, step_ms_ = 0, step_cpu_ms_ = 0;
  double step_seconds_sum_ = 0, step_cpu_seconds_sum_ = 0;
  long step_count_ = 0;

  std::function<void()> on_publish_;
  std::thread thread_;
};

}  // namespace jelly::viewer
