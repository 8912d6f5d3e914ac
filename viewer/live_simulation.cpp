#include <jelly/viewer/live_simulation.hpp>

#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::viewer {

namespace {

using Clock = std::chrono::steady_clock;

double now_seconds() {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// A time for a message: 4 significant digits (0.3333, not 0.33333399999999996).
std::string time_text(Real t) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", t);
  return text;
}

// CPU time of the calling thread (what a step costs, whatever else runs on the machine).
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

LiveSettings LiveSettings::of(const Scene& scene) {
  LiveSettings s;
  s.integrator = scene.integrator.name;
  s.dt = scene.integrator.dt;
  for (const BodySpec& body : scene.bodies) s.springs.push_back(body.material.springs);
  s.gravity = scene.gravity;
  for (const auto& t : scene.terrains) s.contacts.push_back(t->contact);
  return s;
}

Scene LiveSettings::applied_to(Scene scene) const {
  if (scene.integrator.name != integrator) scene.integrator.options = {};
  scene.integrator.name = integrator;
  scene.integrator.dt = dt;
  for (size_t i = 0; i < scene.bodies.size() && i < springs.size(); ++i)
    scene.bodies[i].material.springs = springs[i];
  scene.gravity = gravity;
  for (size_t i = 0; i < scene.terrains.size() && i < contacts.size(); ++i)
    scene.terrains[i]->contact = contacts[i];
  return scene;
}

LiveSimulation::LiveSimulation(Scene scene, bool threaded, std::function<void()> on_publish)
    : scene_(std::move(scene)),
      settings_(LiveSettings::of(scene_)),
      on_publish_(std::move(on_publish)) {
  scene_.validate();
  sim_scene_ = scene_;
  sim_settings_ = settings_;
  rebuild(sim_scene_, false);
  rate_wall_ = now_seconds();
  publish();
  refresh();
  if (threaded) thread_ = std::thread([this] { loop(); });
}

LiveSimulation::~LiveSimulation() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  finish_recording();
}

void LiveSimulation::set_playing(bool playing) {
  playing_ = playing;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.playing = playing;
  }
  wake_.notify_all();
}

void LiveSimulation::step_once() {
  playing_ = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.playing = false;
    pending_.step = true;
  }
  wake_.notify_all();
}

void LiveSimulation::reset() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.reset = true;
  }
  wake_.notify_all();
}

void LiveSimulation::load(Scene scene) {
  scene.validate();
  scene_ = std::move(scene);
  settings_ = LiveSettings::of(scene_);
  ++generation_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.scene = scene_;
    pending_.settings.reset();
    pending_.reset = false;
  }
  wake_.notify_all();
}

void LiveSimulation::set_speed(double speed) {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.speed = speed;
}

void LiveSimulation::apply(const LiveSettings& settings) {
  const Scene checked = settings.applied_to(scene_);
  checked.validate();
  make_integrator(checked.integrator.name, checked.integrator.options);
  settings_ = settings;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.settings = settings;
  }
  wake_.notify_all();
}

void LiveSimulation::set_drag(std::optional<AnchorSpring> drag) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.drag_changed = true;
    pending_.drag = drag;
  }
  wake_.notify_all();
}

void LiveSimulation::start_recording(const std::string& path) {
  std::error_code error;
  for (const std::string& p : {path, xdmf_path_for(path)})
    if (std::filesystem::exists(p, error))
      throw InputError("recording", p,
                       "a file that does not exist yet (a recording never replaces a file)");
  recording_ = true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.record_to = path;
    pending_.recording_request = ++recording_requests_;
  }
  wake_.notify_all();
}

void LiveSimulation::stop_recording() {
  recording_ = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.record_to.reset();
    pending_.stop_recording = true;
    pending_.recording_request = ++recording_requests_;
  }
  wake_.notify_all();
}

void LiveSimulation::record_if_due() {
  if (!recorder_) return;
  const Real t = sim_->state().t, dt = sim_->options().dt;
  if (t < record_next_ - 1e-9 * dt) return;
  const Real interval = sim_scene_.output_interval > 0 ? sim_scene_.output_interval : 1.0 / 60;
  try {
    // The simulator's own output clock (which only run_until() moves) set to this frame, so
    // that the checkpoints the recorder takes say when the next frame is due, as a run's do.
    sim_->set_output_interval(interval);
    recorder_->on_frame(*sim_);
    ++record_frames_;
  } catch (const std::exception& e) {
    record_error_ = e.what();
    finish_recording();
    return;
  }
  while (record_next_ <= t + 1e-9 * dt) record_next_ += interval;
}

void LiveSimulation::finish_recording() {
  if (!recorder_) return;
  try {
    if (record_scene_changed_)
      recorder_->set_scene(scene_to_json(sim_scene_), sim_scene_.integrator.name);
    RunReport report;
    report.status = status_;
    report.reason = message_;
    report.t = sim_->state().t;
    report.steps = steps_;
    recorder_->on_finish(*sim_, report);
  } catch (const std::exception& e) {
    record_error_ = e.what();
  }
  recorder_.reset();
  record_scene_changed_ = false;
}

void LiveSimulation::rebuild(const Scene& scene, bool keep_state) {
  State state;
  if (keep_state && sim_) state = sim_->state();
  auto sim = std::make_unique<Simulator>(make_simulator(scene));
  if (keep_state && state.x.size() == sim->model().num_dofs()) sim->set_state(std::move(state));
  sim_ = std::move(sim);
  if (drag_ && drag_->particle < sim_->model().num_particles()) sim_->set_anchors({*drag_});
}

void LiveSimulation::apply_live(const LiveSettings& settings) {
  const LiveSettings& old = sim_settings_;
  if (settings.integrator != old.integrator)
    sim_->set_integrator(
        make_integrator(sim_scene_.integrator.name, sim_scene_.integrator.options));
  if (settings.dt != old.dt) sim_->set_dt(settings.dt);
  if (settings.gravity != old.gravity) sim_->set_gravity(settings.gravity);
  const int bodies = static_cast<int>(sim_->model().bodies.size());
  for (int b = 0; b < bodies && b < static_cast<int>(settings.springs.size()); ++b)
    for (int type = 0; type < kSpringTypeCount; ++type) {
      const SpringCoefficients& c = settings.springs[b][type];
      if (b < static_cast<int>(old.springs.size()) && c.ks == old.springs[b][type].ks &&
          c.kd == old.springs[b][type].kd)
        continue;
      sim_->set_spring_coefficients(b, static_cast<SpringType>(type), c);
    }
  // The panel edits a terrain's coefficients, never its contact model; the terrains are the
  // simulator's own (its list is const, the terrains in it are not).
  const Terrains& terrains = sim_->terrains();
  for (size_t i = 0; i < terrains.size() && i < settings.contacts.size(); ++i)
    terrains[i]->set_contact(settings.contacts[i]);
}

bool LiveSimulation::take_commands() {
  Commands c;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    c = std::move(pending_);
    pending_ = Commands{};
  }
  bool changed = false;
  if (c.speed) speed_ = *c.speed;
  if (c.recording_request > 0) {
    record_request_ = c.recording_request;
    changed = true;
  }
  // A recording is one run of one model: a stop, a reset or a new scene ends it (before the
  // new scene or settings replace the ones it stores).
  if (c.stop_recording || c.reset || c.scene) finish_recording();
  if (c.scene) {
    sim_scene_ = std::move(*c.scene);
    sim_settings_ = LiveSettings::of(sim_scene_);
    ++sim_generation_;
    drag_.reset();
    c.reset = true;
  }
  if (c.drag_changed) {
    drag_ = c.drag;
    if (drag_ && drag_->particle >= sim_->model().num_particles()) drag_.reset();
    sim_->set_anchors(drag_ ? AnchorSprings{*drag_} : AnchorSprings{});
    changed = true;
  }
  if (c.settings) {
    // The running simulator takes the new settings and goes on from the current state; a reset
    // rebuilds it from the scene with them.
    sim_scene_ = c.settings->applied_to(std::move(sim_scene_));
    if (recorder_) record_scene_changed_ = true;
    if (!c.reset) apply_live(*c.settings);
    sim_settings_ = *c.settings;
    changed = true;
  }
  if (c.reset) {
    rebuild(sim_scene_, false);
    steps_ = 0;
    stopped_ = false;
    status_ = RunStatus::kCompleted;
    message_.clear();
    changed = true;
  }
  if (c.playing) {
    sim_playing_ = *c.playing && !stopped_;
    changed = true;
  }
  if (c.record_to) {
    finish_recording();
    record_error_.clear();
    record_frames_ = 0;
    record_path_ = *c.record_to;
    try {
      RecorderOptions options;
      options.scene_json = scene_to_json(sim_scene_);
      options.integrator_name = sim_scene_.integrator.name;
      recorder_ = std::make_unique<H5Recorder>(record_path_, *sim_, options);
      record_next_ = sim_->state().t;
      record_if_due();
    } catch (const std::exception& e) {
      record_error_ = e.what();
      recorder_.reset();
    }
  }
  if (c.step && !stopped_) {
    step();
    changed = true;
  }
  return changed;
}

bool LiveSimulation::step() {
  if (stopped_) return false;
  const double start = now_seconds(), start_cpu = thread_cpu_seconds();
  try {
    const StepResult r = sim_->step();
    if (!r.ok) {
      status_ = RunStatus::kSolverFailed;
      message_ = "the solver failed at t = " + time_text(sim_->state().t) + " s" + ": " + r.message;
    } else if (auto why = sim_->options().divergence.check(sim_->model(), sim_->state())) {
      status_ = RunStatus::kDiverged;
      message_ = "diverged at t = " + time_text(sim_->state().t) + " s: " + *why;
    }
  } catch (const std::exception& e) {
    status_ = RunStatus::kSolverFailed;
    message_ = e.what();
  }
  step_seconds_sum_ += now_seconds() - start;
  step_cpu_seconds_sum_ += thread_cpu_seconds() - start_cpu;
  ++step_count_;
  if (status_ != RunStatus::kCompleted) {
    stopped_ = true;
    sim_playing_ = false;
    finish_recording();  // with the guard's reason as the run's
    return false;
  }
  ++steps_;
  record_if_due();
  return true;
}

void LiveSimulation::publish() {
  const double now = now_seconds();
  const State& s = sim_->state();
  if (now - rate_wall_ >= 0.5 || !sim_playing_) {
    const double span = now - rate_wall_;
    if (span > 0 && sim_playing_) {
      steps_per_second_ = static_cast<double>(steps_ - rate_steps_) / span;
      sim_rate_ = (s.t - rate_t_) / span;
    } else if (!sim_playing_) {
      steps_per_second_ = sim_rate_ = 0;
    }
    if (step_count_ > 0) {
      step_ms_ = 1e3 * step_seconds_sum_ / static_cast<double>(step_count_);
      step_cpu_ms_ = 1e3 * step_cpu_seconds_sum_ / static_cast<double>(step_count_);
    }
    step_seconds_sum_ = step_cpu_seconds_sum_ = 0;
    step_count_ = 0;
    rate_wall_ = now;
    rate_steps_ = steps_;
    rate_t_ = s.t;
  }
  LiveFrame& f = frames_[back_];
  f.generation = sim_generation_;
  f.t = s.t;
  f.steps = steps_;
  f.x = s.x;
  const Model& m = sim_->model();
  f.kinetic = kinetic_energy(m, s.v);
  f.elastic = elastic_energy(m, s.x);
  f.gravitational = gravitational_energy(m, s.x);
  f.center_of_mass = center_of_mass(m, s.x);
  f.steps_per_second = steps_per_second_;
  f.sim_seconds_per_second = sim_rate_;
  f.step_milliseconds = step_ms_;
  f.step_cpu_milliseconds = step_cpu_ms_;
  f.playing = sim_playing_;
  f.status = status_;
  f.message = message_;
  f.recording = recorder_ != nullptr;
  f.recording_path = record_path_;
  f.recorded_frames = record_frames_;
  f.recording_error = record_error_;
  f.recording_request = record_request_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::swap(back_, middle_);
    fresh_ = true;
  }
  if (on_publish_) on_publish_();
}

bool LiveSimulation::refresh() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!fresh_) return false;
    std::swap(front_, middle_);
    fresh_ = false;
  }
  const LiveFrame& f = frames_[front_];
  if (!f.playing && f.generation == generation_) playing_ = false;
  // The simulation ended the recording itself (a reset, a stop, a failed write).
  if (f.recording_request == recording_requests_ && !f.recording) recording_ = false;
  return true;
}

void LiveSimulation::advance_to(Real t_end) {
  take_commands();
  const Real dt = sim_->options().dt;
  sim_playing_ = !stopped_;  // lockstep always plays (for the rates the panel shows)
  while (!stopped_ && sim_->state().t < t_end - 0.5 * dt) step();
  playing_ = !stopped_;  // (the caller's thread is the UI's in lockstep)
  publish();
}

void LiveSimulation::loop() {
  double pace_wall = now_seconds();
  Real pace_t = sim_->state().t;
  for (;;) {
    bool changed = false;
    try {
      changed = take_commands();
    } catch (const std::exception& e) {
      status_ = RunStatus::kSolverFailed;
      message_ = e.what();
      stopped_ = true;
      sim_playing_ = false;
      changed = true;
    }
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (quit_) return;
      if (!sim_playing_) {
        lock.unlock();
        if (changed) publish();
        lock.lock();
        wake_.wait_for(lock, std::chrono::milliseconds(100));
        pace_wall = now_seconds();
        pace_t = sim_->state().t;
        continue;
      }
    }
    if (changed) {
      pace_wall = now_seconds();
      pace_t = sim_->state().t;
    }
    // A batch of steps for at most one display frame of wall time, or until the simulation is
    // ahead of the paced clock.
    const double batch_end = now_seconds() + 1.0 / 60;
    bool ahead = false;
    for (double now = now_seconds(); now < batch_end; now = now_seconds()) {
      if (speed_ > 0 && sim_->state().t >= pace_t + speed_ * (now - pace_wall)) {
        ahead = true;
        break;
      }
      const Real dt = sim_->options().dt;
      const bool before_end = sim_->state().t < sim_scene_.duration - 0.5 * dt;
      if (!step()) break;
      // The run pauses where the scene ends (as `jelly run` stops there); Play goes on past it.
      if (before_end && sim_->state().t >= sim_scene_.duration - 0.5 * dt) {
        sim_playing_ = false;
        break;
      }
    }
    publish();
    const double now = now_seconds();
    // Behind by more than a fifth of a second: the machine is too slow for this speed; do not
    // try to catch up later.
    if (speed_ > 0 && pace_t + speed_ * (now - pace_wall) - sim_->state().t > 0.2 * speed_) {
      pace_wall = now;
      pace_t = sim_->state().t;
    }
    if (ahead) {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(4));
    }
  }
}

}  // namespace jelly::viewer
