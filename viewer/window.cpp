#include <jelly/viewer/window.hpp>

#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <jelly/viewer/detail/gl.hpp>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/viewer/detail/ray_triangle.hpp>
#include <jelly/viewer/image_io.hpp>
#include <jelly/viewer/recording_view.hpp>
#include <jelly/viewer/render_target.hpp>
#include <jelly/viewer/renderer.hpp>
#include <jelly/viewer/scene_builder.hpp>

namespace jelly::viewer {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// CPU time of the calling thread (with LP_NUM_THREADS=0 llvmpipe draws on it too).
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::string glfw_error;  // the last message of GLFW's error callback

// A fixed-size history of one value per published frame, for the plots (no allocation).
class History {
 public:
  static constexpr int kCapacity = 600;
  void push(float v) {
    values_[static_cast<size_t>(head_)] = v;
    head_ = (head_ + 1) % kCapacity;
    size_ = std::min(size_ + 1, kCapacity);
  }
  void clear() { head_ = size_ = 0; }
  int size() const { return size_; }
  // The i-th oldest value.
  float at(int i) const {
    return values_[static_cast<size_t>((head_ - size_ + i + kCapacity) % kCapacity)];
  }
  float last() const { return size_ > 0 ? at(size_ - 1) : 0.0f; }

 private:
  std::array<float, kCapacity> values_{};
  int head_ = 0, size_ = 0;
};

// Several series in one plot with their own colours and a legend line underneath.
void plot(const char* id, const std::vector<const History*>& series,
          const std::vector<const char*>& names, const std::vector<ImU32>& colors,
          float height = 90) {
  const float width = ImGui::GetContentRegionAvail().x;
  const ImVec2 a = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, ImVec2(width, height));
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImVec2 b(a.x + width, a.y + height);
  draw->AddRectFilled(a, b, IM_COL32(30, 32, 38, 255));
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  int count = 0;
  for (const History* h : series) {
    count = std::max(count, h->size());
    for (int i = 0; i < h->size(); ++i) {
      lo = std::min(lo, h->at(i));
      hi = std::max(hi, h->at(i));
    }
  }
  if (count >= 2 && lo <= hi) {
    if (hi - lo < 1e-6f * std::max(1.0f, std::abs(hi))) {
      hi += 0.5f;
      lo -= 0.5f;
    }
    const auto point = [&](int i, int n, float v) {
      return ImVec2(a.x +
                        width * static_cast<float>(i) / static_cast<float>(History::kCapacity - 1) +
                        width * static_cast<float>(History::kCapacity - n) /
                            static_cast<float>(History::kCapacity - 1),
                    b.y - 4 - (height - 8) * (v - lo) / (hi - lo));
    };
    for (size_t s = 0; s < series.size(); ++s) {
      const History& h = *series[s];
      for (int i = 1; i < h.size(); ++i)
        draw->AddLine(point(i - 1, h.size(), h.at(i - 1)), point(i, h.size(), h.at(i)), colors[s],
                      1.5f);
    }
    char text[64];
    std::snprintf(text, sizeof text, "%.4g", hi);
    draw->AddText(ImVec2(a.x + 3, a.y + 1), IM_COL32(200, 200, 200, 255), text);
    std::snprintf(text, sizeof text, "%.4g", lo);
    draw->AddText(ImVec2(a.x + 3, b.y - ImGui::GetFontSize() - 1), IM_COL32(200, 200, 200, 255),
                  text);
  }
  // The legend, wrapped to the panel's width.
  const float spacing = ImGui::GetStyle().ItemSpacing.x;
  float used = 0;
  for (size_t s = 0; s < series.size(); ++s) {
    char text[64];
    std::snprintf(text, sizeof text, "%s %.4g", names[s], series[s]->last());
    const float w = ImGui::CalcTextSize(text).x;
    if (s > 0 && used + spacing + w <= width) {
      ImGui::SameLine();
      used += spacing + w;
    } else {
      used = w;
    }
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colors[s]), "%s", text);
  }
}

using detail::ray_triangle;

std::vector<std::string> scenes_beside(const std::string& path) {
  std::vector<std::string> out;
  std::error_code error;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  for (const auto& entry :
       std::filesystem::directory_iterator(folder.empty() ? "." : folder, error)) {
    if (entry.path().extension() == ".json") out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// A new file in `folder`: jelly-<local date>-<time><extension>, with -2, -3, ... before the
// extension when that name (or, for a recording, its XDMF sidecar) is taken.
std::string new_file_name(const std::string& folder, const std::string& extension) {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "jelly-%Y%m%d-%H%M%S", &local);
  std::error_code error;
  for (int k = 1;; ++k) {
    const std::string name = std::string(stamp) + (k > 1 ? "-" + std::to_string(k) : "");
    const std::filesystem::path path = std::filesystem::path(folder) / (name + extension);
    if (std::filesystem::exists(path, error)) continue;
    if (extension == ".h5" &&
        std::filesystem::exists(std::filesystem::path(folder) / (name + ".xdmf"), error))
      continue;
    return path.string();
  }
}

constexpr ImU32 kRed = IM_COL32(235, 90, 80, 255), kGreen = IM_COL32(110, 200, 110, 255),
                kBlue = IM_COL32(100, 150, 240, 255), kYellow = IM_COL32(230, 200, 80, 255);

}  // namespace

struct ViewerWindow::Impl {
  ViewOptions options;
  GLFWwindow* window = nullptr;
  bool imgui = false;
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<RenderTarget> target;
  RenderScene scene;
  Camera camera;
  VecX positions;
  int fb_width = 0, fb_height = 0;
  long frames_shown = 0;

  // Live.
  std::unique_ptr<LiveSimulation> live;
  std::string scene_path;
  std::vector<std::string> scene_files;
  std::unique_ptr<SceneBuilder> builder;
  unsigned long builder_generation = 0;
  Real interval = 1.0 / 60;  // lockstep: simulated time per frame
  LiveSettings edit;         // the panel's copy of the settings
  int spring_body = 0;       // the body whose springs the panel edits
  std::string panel_error;   // a rejected panel input
  char path_buffer[512] = {};
  Real last_t = -1;
  History kinetic, elastic, gravitational, total, com_x, com_y, com_z;
  float pick_stiffness = 0, pick_damping = 0;  // 0: chosen from the model at start
  float speed = 1;
  bool max_speed = false;

  // Replay.
  std::unique_ptr<RecordingView> replay;
  std::unique_ptr<RecordingView::Follow> replay_follow;  // the replay's camera target
  int replay_frame = 0;
  double replay_time = 0;
  bool replay_playing = false;
  bool replay_loop = true;
  float replay_speed = 1;
  std::vector<std::pair<std::string, std::vector<float>>> series;  // observables per frame
  Clock::time_point last_frame_time = Clock::now();

  float panel_right = 0;  // the panel's right edge in pixels, 0 when hidden or collapsed
  std::vector<std::string> clipped_items;  // panel items cut off by its edge, last frame
  std::optional<PanelRect> banner_rect;    // the divergence banner, last frame
  PanelRect panel_rect;                    // the panel, last frame (empty when hidden)
  bool follow = false;  // the camera's target follows the bodies (default without --camera)
  // Live, following: the camera also moves in until the bodies fill the picture (framed as their
  // largest extent so far, so a bounce or a squash does not pump the zoom) until the user zooms
  // (issue 40, items 3 and 9: a jelly sliding down a slope stayed as small as the first framing
  // of its drop made it).
  bool follow_zoom = false;
  Vec3 follow_extent = Vec3::Zero();
  // Recording (live) and screenshots (F12): the current or last files, the last failure.
  std::string record_path, screenshot_path, record_message;
  bool screenshot_pending = false;

  // Mouse.
  enum class Drag { kNone, kOrbit, kPan, kParticle } drag = Drag::kNone;
  double mouse_x = 0, mouse_y = 0;
  int drag_particle = -1;
  Vec3f drag_plane_point = Vec3f::Zero(), drag_plane_normal = Vec3f::UnitZ();
  Vec3f drag_target = Vec3f::Zero();

  // Timing (for --stats and the panel).
  double render_seconds = 0, frame_seconds = 0;
  double render_sum = 0, render_max = 0;
  long render_count = 0;
  Clock::time_point start = Clock::now();
  double render_cpu_sum = 0, frame_cpu_sum = 0;
  double sim_step_ms_sum = 0, sim_step_cpu_ms_sum = 0, sim_rate_sum = 0,
         sim_steps_per_second_sum = 0;
  long sim_samples = 0;

  ~Impl() {
    live.reset();  // stop the simulation thread first
    if (window) glfwMakeContextCurrent(window);
    target.reset();
    renderer.reset();
    if (imgui) {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
      ImGui::DestroyContext();
    }
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
  }

  void open(const std::string& title) {
    glfwSetErrorCallback([](int, const char* message) { glfw_error = message ? message : ""; });
    if (!glfwInit())
      throw DisplayUnavailable("jelly view needs a display and none is available (" + glfw_error +
                               "). Run it on a desktop, under xvfb-run, or use `jelly render` "
                               "to render a recording without a display");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SAMPLES, 0);  // the RenderTarget multisamples
    window = glfwCreateWindow(options.width, options.height, title.c_str(), nullptr, nullptr);
    if (window == nullptr)
      throw DisplayUnavailable("jelly view cannot open an OpenGL 3.3 core window (" + glfw_error +
                               ")");
    glfwMakeContextCurrent(window);
    glfwSwapInterval(options.lockstep || options.frames >= 0 ? 0 : 1);
    glfwSetWindowUserPointer(window, this);
    glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int mods) {
      auto* self = static_cast<Impl*>(glfwGetWindowUserPointer(w));
      double x = 0, y = 0;
      glfwGetCursorPos(w, &x, &y);
      if (action != GLFW_PRESS || !ImGui::GetIO().WantCaptureMouse)
        self->mouse_button(button, action == GLFW_PRESS, x, y, mods);
    });
    glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
      static_cast<Impl*>(glfwGetWindowUserPointer(w))->cursor(x, y);
    });
    glfwSetScrollCallback(window, [](GLFWwindow* w, double, double dy) {
      if (!ImGui::GetIO().WantCaptureMouse)
        static_cast<Impl*>(glfwGetWindowUserPointer(w))->scroll(dy);
    });
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
      if (action != GLFW_PRESS || ImGui::GetIO().WantCaptureKeyboard) return;
      static_cast<Impl*>(glfwGetWindowUserPointer(w))->key(key);
    });
    // ImGui's callbacks call the ones installed above after its own.
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui::GetStyle().WindowRounding = 4;
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    imgui = true;
    renderer = std::make_unique<Renderer>();
    glfwGetFramebufferSize(window, &fb_width, &fb_height);
    target = std::make_unique<RenderTarget>(std::max(fb_width, 1), std::max(fb_height, 1),
                                            options.samples, options.fxaa);
  }

  float aspect() const {
    return static_cast<float>(std::max(fb_width, 1)) / static_cast<float>(std::max(fb_height, 1));
  }

  // The scale from window coordinates (mouse) to framebuffer pixels.
  float pixel_scale() const {
    int w = 0, h = 0;
    glfwGetWindowSize(window, &w, &h);
    return w > 0 ? static_cast<float>(fb_width) / static_cast<float>(w) : 1.0f;
  }

  // ---- Live ------------------------------------------------------------------------------

  void make_builder() {
    const Scene& s = live->scene();
    const Model model = make_model(s);
    Terrains terrains;
    for (const auto& spec : s.terrains) terrains.push_back(spec->make());
    Vec3 lo, hi;
    bounds_of(model.rest_position, lo, hi);
    const bool first = builder == nullptr;
    builder = std::make_unique<SceneBuilder>(model, std::move(terrains), lo, hi);
    builder_generation = live->generation();
    positions = model.rest_position;
    follow_extent = Vec3::Zero();
    const RenderScene old = std::move(scene);
    scene = builder->make_scene(positions, 0);
    if (!first) {
      scene.show_particles = old.show_particles || scene.show_particles;
      scene.show_springs = old.show_springs;
      scene.show_surfaces = old.show_surfaces;
      scene.show_structural_only = old.show_structural_only;
      scene.spring_coloring = old.spring_coloring;
    }
    if (first || pick_stiffness <= 0) {
      const float mass = static_cast<float>(model.mass.sum());
      const float particle = static_cast<float>(model.mass.maxCoeff());
      pick_stiffness = 20.0f * mass;
      pick_damping = std::sqrt(pick_stiffness * particle);
    }
    interval = s.output_interval > 0 ? s.output_interval : 1.0 / 60;
    for (History* h : {&kinetic, &elastic, &gravitational, &total, &com_x, &com_y, &com_z})
      h->clear();
    last_t = -1;
    edit = live->settings();
    drag = Drag::kNone;
    drag_particle = -1;
  }

  void init_live(const Scene& s, const std::string& path) {
    scene_path = path;
    std::snprintf(path_buffer, sizeof path_buffer, "%s", path.c_str());
    scene_files = scenes_beside(path);
    // Each published frame wakes the window if it sleeps (paused, waiting for events).
    live = std::make_unique<LiveSimulation>(s, !options.lockstep, [] { glfwPostEmptyEvent(); });
    live->set_speed(options.speed);
    speed = static_cast<float>(options.speed > 0 ? options.speed : 1);
    max_speed = options.speed <= 0;
    make_builder();
    scene.show_particles = scene.show_particles || options.particles;
    scene.show_springs = options.springs;
    if (!options.camera.empty()) {
      camera.parse(options.camera);
    } else {
      Vec3 lo, hi;
      bounds_of(positions, lo, hi);
      // The bodies and where they will land seen (not hidden in a bowl).
      Sight sight;
      add_sight_points(positions, builder->terrains(), 0, 48, sight.points);
      camera = framing_camera(lo, hi, builder->terrains(), 0, aspect(), {sight});
    }
    follow = options.camera.empty();  // a camera of the user's own stays where it was put
    follow_zoom = follow;
    if (options.record) toggle_recording();
    if (!options.paused && !options.lockstep) live->set_playing(true);
  }

  void update_live() {
    if (options.lockstep) live->advance_to(static_cast<Real>(frames_shown) * interval);
    live->refresh();
    if (live->generation() != builder_generation) make_builder();
    const LiveFrame& f = live->front();
    if (f.generation != builder_generation) return;  // a frame of the scene before a load
    if (f.x.size() == positions.size()) positions = f.x;
    if (f.t != last_t) {
      if (f.t < last_t)
        for (History* h : {&kinetic, &elastic, &gravitational, &total, &com_x, &com_y, &com_z})
          h->clear();
      last_t = f.t;
      kinetic.push(static_cast<float>(f.kinetic));
      elastic.push(static_cast<float>(f.elastic));
      gravitational.push(static_cast<float>(f.gravitational));
      total.push(static_cast<float>(f.kinetic + f.elastic + f.gravitational));
      com_x.push(static_cast<float>(f.center_of_mass.x()));
      com_y.push(static_cast<float>(f.center_of_mass.y()));
      com_z.push(static_cast<float>(f.center_of_mass.z()));
      if (f.playing) {
        sim_step_ms_sum += f.step_milliseconds;
        sim_step_cpu_ms_sum += f.step_cpu_milliseconds;
        sim_rate_sum += f.sim_seconds_per_second;
        sim_steps_per_second_sum += f.steps_per_second;
        ++sim_samples;
      }
    }
    builder->update(positions, f.t, scene);
  }

  // ---- Replay ----------------------------------------------------------------------------

  // A replay with a screenshot (or a frame count) shows one recorded frame per window frame,
  // unless started paused.
  bool replay_lockstep() const {
    return !options.paused &&
           (options.lockstep || options.frames >= 0 || !options.screenshot.empty());
  }

  void init_replay(const std::string& path) {
    replay = std::make_unique<RecordingView>(path);
    replay_frame = std::clamp(options.start_frame, 0, replay->frames() - 1);
    replay_time = replay->recording().time[replay_frame];
    replay_playing = !options.paused && options.frames < 0 && options.screenshot.empty();
    scene = replay->make_scene(replay_frame);
    scene.show_particles = scene.show_particles || options.particles;
    scene.show_springs = options.springs;
    positions = replay->recording().position[replay_frame];
    // The camera `jelly render` follows the bodies with over the whole recording, so a replay's
    // frame and the video's are the same picture.
    std::vector<int> all(static_cast<size_t>(replay->frames()));
    for (int k = 0; k < replay->frames(); ++k) all[static_cast<size_t>(k)] = k;
    replay_follow = std::make_unique<RecordingView::Follow>(*replay, all, aspect());
    camera = replay_follow->at(replay_frame);
    if (!options.camera.empty()) camera.parse(options.camera);
    follow = options.camera.empty();
    // The recorded observables to plot, one value per frame (the height of the centre of mass).
    const Recording& r = replay->recording();
    for (const char* name : {"kinetic_energy", "elastic_energy", "gravitational_energy",
                             "total_energy", "center_of_mass"}) {
      const auto it = r.observables.find(name);
      if (it == r.observables.end() || it->second.rows() != r.frames()) continue;
      const Eigen::MatrixXd& m = it->second;
      std::vector<float> values(static_cast<size_t>(m.rows()));
      for (Eigen::Index i = 0; i < m.rows(); ++i)
        values[static_cast<size_t>(i)] = static_cast<float>(m(i, m.cols() == 3 ? 1 : 0));
      series.emplace_back(std::string(name) + (m.cols() == 3 ? ".y" : ""), std::move(values));
    }
  }

  void update_replay(double wall_dt) {
    const auto& time = replay->recording().time;
    if (replay_lockstep()) {
      // Window frame k shows recorded frame start + k, so `--frames N --screenshot` captures
      // recorded frame start + N (the last one when the recording is shorter).
      replay_frame = static_cast<int>(
          std::min<long>(options.start_frame + frames_shown, replay->frames() - 1));
      replay_frame = std::max(replay_frame, 0);
      replay_time = time[static_cast<size_t>(replay_frame)];
    } else if (replay_playing) {
      replay_time += wall_dt * replay_speed;
      if (replay_time > time.back()) {
        if (replay_loop) {
          replay_time = time.front();
        } else {
          replay_time = time.back();
          replay_playing = false;
        }
      }
      replay_frame = replay->frame_at(replay_time);
    }
    replay->update(replay_frame, scene);
    positions = replay->recording().position[replay_frame];
  }

  // ---- Input -----------------------------------------------------------------------------

  // The particle under window position (x, y): the body surface hit first, then the particle of
  // that body nearest the hit; without a hit, the particle nearest the cursor within 12 pixels.
  int pick(double x, double y) const {
    const float s = pixel_scale();
    const float px = static_cast<float>(x) * s, py = static_cast<float>(y) * s;
    Vec3f o, d;
    camera.ray(px, py, fb_width, fb_height, o, d);
    float best = std::numeric_limits<float>::max();
    int body = -1;
    Vec3f hit = Vec3f::Zero();
    if (scene.show_surfaces) {
      for (size_t b = 0; b < scene.bodies.size(); ++b) {
        const auto& p = scene.bodies[b].positions;
        const auto at = [&p](int v) { return Vec3f(p[3 * v], p[3 * v + 1], p[3 * v + 2]); };
        for (const auto& t : scene.bodies[b].triangles) {
          const float u = ray_triangle(o, d, at(t[0]), at(t[1]), at(t[2]));
          if (u > 0 && u < best) {
            best = u;
            body = static_cast<int>(b);
          }
        }
      }
    }
    const int n = static_cast<int>(positions.size() / 3);
    int chosen = -1;
    if (body >= 0) {
      hit = o + best * d;
      const BodySurface& surface = builder->surfaces()[static_cast<size_t>(body)];
      float nearest = std::numeric_limits<float>::max();
      for (int i = surface.first_particle; i < surface.first_particle + surface.num_particles;
           ++i) {
        const float dist = (positions.segment<3>(3 * i).cast<float>() - hit).squaredNorm();
        if (dist < nearest) {
          nearest = dist;
          chosen = i;
        }
      }
      return chosen;
    }
    float nearest_depth = std::numeric_limits<float>::max();
    const float radius = 12.0f * s;
    for (int i = 0; i < n; ++i) {
      const Vec3f p = positions.segment<3>(3 * i).cast<float>();
      const auto q = camera.project(p, fb_width, fb_height);
      if (!q || (q->x() - px) * (q->x() - px) + (q->y() - py) * (q->y() - py) > radius * radius)
        continue;
      const float depth = (p - camera.eye()).dot(camera.forward());
      if (depth < nearest_depth) {
        nearest_depth = depth;
        chosen = i;
      }
    }
    return chosen;
  }

  void send_drag() {
    if (!live) return;
    if (drag_particle < 0) {
      live->set_drag(std::nullopt);
      return;
    }
    live->set_drag(AnchorSpring{drag_particle, drag_target.cast<Real>(),
                                static_cast<Real>(pick_stiffness),
                                static_cast<Real>(pick_damping)});
  }

  void mouse_button(int button, bool press, double x, double y, int mods) {
    mouse_x = x;
    mouse_y = y;
    if (!press) {
      if (drag == Drag::kParticle) {
        drag_particle = -1;
        send_drag();
      }
      drag = Drag::kNone;
      return;
    }
    const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
    if (button == GLFW_MOUSE_BUTTON_LEFT && !shift) {
      const int p = live ? pick(x, y) : -1;
      if (p >= 0) {
        drag = Drag::kParticle;
        drag_particle = p;
        drag_plane_point = positions.segment<3>(3 * p).cast<float>();
        drag_plane_normal = camera.forward();
        drag_target = drag_plane_point;
        send_drag();
      } else {
        drag = Drag::kOrbit;
      }
    } else if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE ||
               (button == GLFW_MOUSE_BUTTON_LEFT && shift)) {
      drag = Drag::kPan;
    }
  }

  void cursor(double x, double y) {
    const double dx = x - mouse_x, dy = y - mouse_y;
    mouse_x = x;
    mouse_y = y;
    switch (drag) {
      case Drag::kOrbit:
        camera.orbit(static_cast<float>(-0.3 * dx), static_cast<float>(0.3 * dy));
        break;
      case Drag::kPan:
        camera.pan(static_cast<float>(dx) * pixel_scale(), static_cast<float>(dy) * pixel_scale(),
                   fb_height);
        break;
      case Drag::kParticle: {
        const float s = pixel_scale();
        Vec3f o, d;
        camera.ray(static_cast<float>(x) * s, static_cast<float>(y) * s, fb_width, fb_height, o, d);
        const float denominator = drag_plane_normal.dot(d);
        if (std::abs(denominator) > 1e-6f) {
          drag_target = o + d * (drag_plane_normal.dot(drag_plane_point - o) / denominator);
          send_drag();
        }
        break;
      }
      case Drag::kNone:
        break;
    }
  }

  void scroll(double dy) {
    camera.zoom(static_cast<float>(std::pow(0.9, dy)));
    follow_zoom = false;  // the user's distance is kept
  }

  void key(int key) {
    switch (key) {
      case GLFW_KEY_SPACE:
        if (live)
          live->set_playing(!live->playing());
        else
          replay_playing = !replay_playing;
        break;
      case GLFW_KEY_S:
        if (live)
          live->step_once();
        else
          replay_frame = std::min(replay_frame + 1, replay->frames() - 1);
        break;
      case GLFW_KEY_R:
        if (live)
          live->reset();
        else
          replay_frame = 0, replay_time = replay->recording().time.front();
        break;
      case GLFW_KEY_H:
        options.hide_panel = !options.hide_panel;
        break;
      case GLFW_KEY_P:
        scene.show_particles = !scene.show_particles;
        break;
      case GLFW_KEY_L:
        scene.show_springs = !scene.show_springs;
        break;
      case GLFW_KEY_F9:
        toggle_recording();
        break;
      case GLFW_KEY_F12:
        screenshot_pending = true;  // taken when this frame is drawn
        break;
      case GLFW_KEY_ESCAPE:
        glfwSetWindowShouldClose(window, GLFW_TRUE);
        break;
      default:
        break;
    }
  }

  void toggle_recording() {
    if (!live) return;
    if (live->recording()) {
      live->stop_recording();
      return;
    }
    try {
      const std::string path = new_file_name(options.record_dir, ".h5");
      live->start_recording(path);
      record_path = path;
      record_message.clear();
    } catch (const InputError& e) {
      record_message = e.what();
    }
  }

  // The Record button, the screenshot button and what they wrote.
  void record_lines() {
    if (live) {
      if (ImGui::Button(live->recording() ? "Stop recording" : "Record")) toggle_recording();
      ImGui::SameLine();
    }
    if (ImGui::Button("Screenshot")) screenshot_pending = true;
    ImGui::SameLine();
    ImGui::TextDisabled(live ? "F9, F12" : "F12");
    if (live) {
      const LiveFrame& f = live->front();
      if (live->recording() || f.recording) {
        ImGui::TextColored(ImVec4(1, 0.3f, 0.25f, 1), "REC %s: %ld frames", record_path.c_str(),
                           f.recorded_frames);
      } else if (!f.recording_path.empty() && f.recording_error.empty()) {
        ImGui::TextDisabled("recorded %s (%ld frames)", f.recording_path.c_str(),
                            f.recorded_frames);
      }
      if (!f.recording_error.empty()) record_message = f.recording_error;
    }
    if (!screenshot_path.empty()) ImGui::TextDisabled("screenshot %s", screenshot_path.c_str());
    if (!record_message.empty()) {
      ImGui::PushTextWrapPos(0);
      ImGui::TextColored(ImVec4(1, 0.6f, 0.2f, 1), "%s", record_message.c_str());
      ImGui::PopTextWrapPos();
    }
  }

  // ---- Panel -----------------------------------------------------------------------------

  // Records the last item's label when it reaches past the panel's right edge (cut off).
  void note_clipping(const char* label) {
    const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
    if (ImGui::GetItemRectMax().x > right + 0.5f) clipped_items.emplace_back(label);
  }

  void apply_settings() {
    try {
      live->apply(edit);
      panel_error.clear();
    } catch (const InputError& e) {
      panel_error = e.what();
      edit = live->settings();
    }
  }

  void display_section() {
    if (!ImGui::CollapsingHeader("Display")) return;
    ImGui::Checkbox("surfaces", &scene.show_surfaces);
    ImGui::SameLine();
    ImGui::Checkbox("particles", &scene.show_particles);
    ImGui::SameLine();
    ImGui::Checkbox("springs", &scene.show_springs);
    if (scene.show_springs) {
      ImGui::Checkbox("structural only", &scene.show_structural_only);
      int coloring = scene.spring_coloring == SpringColoring::kStrain ? 1 : 0;
      ImGui::SameLine();
      ImGui::RadioButton("type", &coloring, 0);
      ImGui::SameLine();
      ImGui::RadioButton("strain", &coloring, 1);
      scene.spring_coloring = coloring ? SpringColoring::kStrain : SpringColoring::kType;
    }
    if (ImGui::Checkbox("follow the bodies", &follow)) follow_zoom = follow && !replay;
    ImGui::Checkbox("shadows", &renderer->options().shadows);
    ImGui::SameLine();
    ImGui::Checkbox("grid", &renderer->options().grid);
    if (ImGui::Button("frame the bodies")) {
      Vec3 lo, hi;
      bounds_of(positions, lo, hi);
      const float yaw = camera.yaw_degrees, pitch = camera.pitch_degrees;
      camera = frame_box(lo.cast<float>(), hi.cast<float>(), aspect(), yaw, pitch);
    }
    ImGui::TextDisabled("camera %s", camera.to_string().c_str());
  }

  void timing_lines() {
    ImGui::Text("%.0f frames/s, draw %.1f ms", frame_seconds > 0 ? 1.0 / frame_seconds : 0.0,
                1e3 * render_seconds);
  }

  void live_panel() {
    const LiveFrame& f = live->front();
    ImGui::Text("%s", scene_path.c_str());
    if (ImGui::Button(live->playing() ? "Pause" : "Play", ImVec2(60, 0)))
      live->set_playing(!live->playing());
    ImGui::SameLine();
    if (ImGui::Button("Step")) live->step_once();
    ImGui::SameLine();
    if (ImGui::Button("Reset")) live->reset();
    ImGui::SameLine();
    if (ImGui::Checkbox("max", &max_speed)) live->set_speed(max_speed ? 0.0 : speed);
    if (!max_speed) {
      if (ImGui::SliderFloat("speed", &speed, 0.05f, 4.0f, "%.2fx real time",
                             ImGuiSliderFlags_Logarithmic))
        live->set_speed(speed);
    }
    ImGui::Text("t = %.3f s, %ld steps", f.t, f.steps);
    ImGui::Text("%.0f steps/s, %.3f sim s per wall s", f.steps_per_second,
                f.sim_seconds_per_second);
    ImGui::Text("step %.3f ms", f.step_milliseconds);
    timing_lines();
    record_lines();
    if (f.status != RunStatus::kCompleted) {
      ImGui::PushTextWrapPos(0);
      ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "Stopped: %s. Reset to go on.",
                         f.message.c_str());
      ImGui::PopTextWrapPos();
    }
    if (!panel_error.empty()) {
      ImGui::PushTextWrapPos(0);
      ImGui::TextColored(ImVec4(1, 0.6f, 0.2f, 1), "%s", panel_error.c_str());
      ImGui::PopTextWrapPos();
    }

    if (ImGui::CollapsingHeader("Scene")) {
      ImGui::InputText("##path", path_buffer, sizeof path_buffer);
      ImGui::SameLine();
      bool load = ImGui::Button("Load");
      if (!scene_files.empty() && ImGui::BeginCombo("scenes", nullptr, ImGuiComboFlags_NoPreview)) {
        for (const std::string& file : scene_files)
          if (ImGui::Selectable(file.c_str())) {
            std::snprintf(path_buffer, sizeof path_buffer, "%s", file.c_str());
            load = true;
          }
        ImGui::EndCombo();
      }
      if (load) {
        try {
          const bool playing = live->playing();
          live->load(load_scene(path_buffer));
          scene_path = path_buffer;
          panel_error.clear();
          live->set_playing(playing);
        } catch (const InputError& e) {
          panel_error = e.what();
        }
      }
    }

    if (ImGui::CollapsingHeader("Integrator", ImGuiTreeNodeFlags_DefaultOpen)) {
      if (ImGui::BeginCombo("method", edit.integrator.c_str())) {
        for (const std::string& name : integrator_names())
          if (ImGui::Selectable(name.c_str(), name == edit.integrator)) {
            edit.integrator = name;
            apply_settings();
          }
        ImGui::EndCombo();
      }
      double dt = edit.dt;
      // A fixed-width field and the presets after it: all of them fit the default panel.
      ImGui::SetNextItemWidth(90);
      if (ImGui::InputDouble("dt (s)", &dt, 0, 0, "%.6g", ImGuiInputTextFlags_EnterReturnsTrue)) {
        edit.dt = dt;
        apply_settings();
      }
      note_clipping("dt (s)");
      for (const auto& [label, value] :
           {std::pair{"1/1000", 1e-3}, {"1/240", 1.0 / 240}, {"1/60", 1.0 / 60}}) {
        ImGui::SameLine();
        if (ImGui::SmallButton(label)) {
          edit.dt = value;
          apply_settings();
        }
        note_clipping(label);
      }
      ImGui::TextDisabled("(applied now, from the current state)");
    }

    if (ImGui::CollapsingHeader("Springs and gravity", ImGuiTreeNodeFlags_DefaultOpen)) {
      bool changed = false;
      // Each body keeps its own coefficients; the panel edits one body's at a time.
      const std::vector<BodySpec>& bodies = live->scene().bodies;
      const int body_count = static_cast<int>(std::min(bodies.size(), edit.springs.size()));
      spring_body = std::clamp(spring_body, 0, std::max(0, body_count - 1));
      if (body_count > 0) {
        if (body_count > 1 &&
            ImGui::BeginCombo("body", bodies[static_cast<size_t>(spring_body)].name.c_str())) {
          for (int b = 0; b < body_count; ++b)
            if (ImGui::Selectable(bodies[static_cast<size_t>(b)].name.c_str(), b == spring_body))
              spring_body = b;
          ImGui::EndCombo();
        }
        auto& springs = edit.springs[static_cast<size_t>(spring_body)];
        for (int type = 0; type < kSpringTypeCount; ++type) {
          ImGui::PushID(type);
          const std::string name(spring_type_name(static_cast<SpringType>(type)));
          float ks = static_cast<float>(springs[type].ks);
          float kd = static_cast<float>(springs[type].kd);
          ImGui::SetNextItemWidth(110);
          if (ImGui::DragFloat("##ks", &ks, std::max(1.0f, 0.01f * ks), 0.0f, 1e7f, "ks %.4g")) {
            springs[type].ks = std::max(0.0f, ks);
            changed = true;
          }
          ImGui::SameLine();
          ImGui::SetNextItemWidth(90);
          if (ImGui::DragFloat("##kd", &kd, std::max(0.1f, 0.01f * kd), 0.0f, 1e6f, "kd %.4g")) {
            springs[type].kd = std::max(0.0f, kd);
            changed = true;
          }
          ImGui::SameLine();
          ImGui::TextUnformatted(name.c_str());
          ImGui::PopID();
        }
      }
      float g[3] = {static_cast<float>(edit.gravity.x()), static_cast<float>(edit.gravity.y()),
                    static_cast<float>(edit.gravity.z())};
      if (ImGui::DragFloat3("gravity", g, 0.05f, -100, 100, "%.3g")) {
        edit.gravity = Vec3(g[0], g[1], g[2]);
        changed = true;
      }
      if (changed) apply_settings();
      ImGui::TextDisabled("(applied live)");
    }

    if (!edit.contacts.empty() && ImGui::CollapsingHeader("Contact")) {
      for (size_t i = 0; i < edit.contacts.size(); ++i) {
        ImGui::PushID(static_cast<int>(i));
        ContactParams& c = edit.contacts[i];
        ImGui::Text("terrain %zu (%s)", i, std::string(contact_model_name(c.model)).c_str());
        float restitution = static_cast<float>(c.restitution);
        float friction = static_cast<float>(c.friction);
        if (ImGui::SliderFloat("restitution", &restitution, 0, 1)) c.restitution = restitution;
        if (ImGui::IsItemDeactivatedAfterEdit()) apply_settings();
        if (ImGui::SliderFloat("friction", &friction, 0, 2)) {
          c.friction = friction;
          c.static_friction = std::max(c.static_friction, c.friction);
        }
        if (ImGui::IsItemDeactivatedAfterEdit()) apply_settings();
        ImGui::PopID();
      }
    }

    if (ImGui::CollapsingHeader("Mouse drag")) {
      ImGui::SliderFloat("stiffness", &pick_stiffness, 10, 1e6f, "%.4g N/m",
                         ImGuiSliderFlags_Logarithmic);
      ImGui::SliderFloat("damping", &pick_damping, 0, 1e4f, "%.4g N s/m",
                         ImGuiSliderFlags_Logarithmic);
      ImGui::TextDisabled("left-drag a body; the spring enters implicit solves");
    }

    display_section();

    if (ImGui::CollapsingHeader("Plots", ImGuiTreeNodeFlags_DefaultOpen)) {
      ImGui::TextDisabled("energies (J), last %d frames", History::kCapacity);
      plot("energies", {&kinetic, &elastic, &gravitational, &total},
           {"kin", "ela", "grav", "total"}, {kRed, kGreen, kBlue, kYellow});
      ImGui::TextDisabled("centre of mass (m)");
      plot("com", {&com_x, &com_y, &com_z}, {"x", "y", "z"}, {kRed, kGreen, kBlue});
    }
  }

  void replay_panel() {
    const Recording& r = replay->recording();
    ImGui::Text("%d frames, t %.3g to %.3g s", r.frames(), r.time.front(), r.time.back());
    if (ImGui::Button(replay_playing ? "Pause" : "Play", ImVec2(60, 0)))
      replay_playing = !replay_playing;
    ImGui::SameLine();
    if (ImGui::Button("<")) replay_frame = std::max(0, replay_frame - 1);
    ImGui::SameLine();
    if (ImGui::Button(">")) replay_frame = std::min(r.frames() - 1, replay_frame + 1);
    ImGui::SameLine();
    ImGui::Checkbox("loop", &replay_loop);
    if (ImGui::SliderInt("frame", &replay_frame, 0, r.frames() - 1)) replay_playing = false;
    replay_frame = std::clamp(replay_frame, 0, r.frames() - 1);
    if (!replay_playing) replay_time = r.time[replay_frame];
    ImGui::SliderFloat("speed", &replay_speed, 0.05f, 4.0f, "%.2fx", ImGuiSliderFlags_Logarithmic);
    ImGui::Text("t = %.4f s, step %ld", r.time[replay_frame], r.step[replay_frame]);
    timing_lines();
    record_lines();
    display_section();
    if (!series.empty() && ImGui::CollapsingHeader("Observables", ImGuiTreeNodeFlags_DefaultOpen)) {
      for (const auto& [name, values] : series) {
        char overlay[96];
        std::snprintf(overlay, sizeof overlay, "%s %.5g", name.c_str(),
                      values[static_cast<size_t>(replay_frame)]);
        ImGui::PushID(name.c_str());
        ImGui::PlotLines("##plot", values.data(), static_cast<int>(values.size()), 0, overlay,
                         FLT_MAX, FLT_MAX, ImVec2(ImGui::GetContentRegionAvail().x, 48));
        ImGui::PopID();
        // The current frame.
        const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
        const float x = lo.x + (hi.x - lo.x) * static_cast<float>(replay_frame) /
                                   static_cast<float>(std::max(1, r.frames() - 1));
        ImGui::GetWindowDrawList()->AddLine(ImVec2(x, lo.y), ImVec2(x, hi.y), kYellow);
      }
    }
    if (ImGui::CollapsingHeader("Run")) {
      if (ImGui::BeginTable("attributes", 2,
                            ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
        for (const auto& [name, value] : r.attributes) {
          if (name == "scene_json") continue;
          ImGui::TableNextRow();
          ImGui::TableNextColumn();
          ImGui::TextUnformatted(name.c_str());
          ImGui::TableNextColumn();
          ImGui::TextUnformatted(value.c_str());
        }
        ImGui::EndTable();
      }
    }
  }

  void overlays() {
    // The divergence guard's message over the picture, so it is seen with the panel hidden.
    banner_rect.reset();
    if (live && live->front().status != RunStatus::kCompleted) {
      // Centred in the part of the picture the panel leaves free, wrapped to its width.
      const ImGuiViewport* viewport = ImGui::GetMainViewport();
      const float left = viewport->WorkPos.x + (options.hide_panel ? 0.0f : panel_right) + 8;
      const float right = viewport->WorkPos.x + viewport->WorkSize.x - 8;
      const float width = std::max(120.0f, right - left);
      ImGui::SetNextWindowPos(ImVec2(0.5f * (left + right), viewport->WorkPos.y + 20),
                              ImGuiCond_Always, ImVec2(0.5f, 0));
      ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(width, viewport->WorkSize.y));
      ImGui::SetNextWindowBgAlpha(0.8f);
      ImGui::Begin("stopped", nullptr,
                   ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                       ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings);
      ImGui::PushTextWrapPos(width - 2 * ImGui::GetStyle().WindowPadding.x);
      ImGui::TextColored(ImVec4(1, 0.4f, 0.35f, 1), "The simulation stopped: %s",
                         live->front().message.c_str());
      ImGui::TextUnformatted(
          "Press R or Reset to start again (try a smaller dt or implicit_euler).");
      ImGui::PopTextWrapPos();
      const ImVec2 pos = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
      banner_rect = PanelRect{pos.x, pos.y, pos.x + size.x, pos.y + size.y};
      ImGui::End();
    }
  }

  void panel() {
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(360, static_cast<float>(std::max(200, fb_height - 16))),
                             ImGuiCond_FirstUseEver);
    const bool open = ImGui::Begin(live ? "jelly view" : "jelly replay");
    if (open) {
      if (live)
        live_panel();
      else
        replay_panel();
    }
    panel_right = open ? ImGui::GetWindowPos().x + ImGui::GetWindowSize().x : 0.0f;
    const ImVec2 pos = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
    panel_rect = PanelRect{pos.x, pos.y, pos.x + (open ? size.x : 0), pos.y + size.y};
    ImGui::End();
  }

  // ---- Frame -----------------------------------------------------------------------------

  bool frame() {
    const double frame_cpu_start = thread_cpu_seconds();
    // Nothing moves while paused: sleep until an event (or a quarter second) instead of
    // drawing the same picture again.
    const bool moving = options.lockstep || options.frames >= 0 || drag != Drag::kNone ||
                        frames_shown < 2 || (live ? live->playing() : replay_playing);
    if (moving)
      glfwPollEvents();
    else
      glfwWaitEventsTimeout(0.25);
    if (glfwWindowShouldClose(window)) return false;
    const double wall_dt = seconds_since(last_frame_time);
    last_frame_time = Clock::now();
    frame_seconds = 0.9 * frame_seconds + 0.1 * wall_dt;
    glfwGetFramebufferSize(window, &fb_width, &fb_height);
    if (fb_width <= 0 || fb_height <= 0) return true;  // minimised

    if (live)
      update_live();
    else
      update_replay(frames_shown == 0 ? 0.0 : wall_dt);
    scene.drag =
        drag == Drag::kParticle && drag_particle >= 0 && 3 * drag_particle + 2 < positions.size();
    if (scene.drag) {
      scene.drag_from = positions.segment<3>(3 * drag_particle).cast<float>();
      scene.drag_to = drag_target;
    }

    // The view's centre in the part of the window the panel leaves free; the camera follows.
    camera.shift_x =
        options.hide_panel
            ? 0.0f
            : std::clamp(panel_right * pixel_scale() / static_cast<float>(fb_width), 0.0f, 0.5f);
    if (follow && replay_follow) {
      camera.target = replay_follow->at(replay_frame).target;
    } else if (follow && positions.size() >= 3) {
      Vec3 lo, hi;
      bounds_of(positions, lo, hi);
      const Vec3 centre = 0.5 * (lo + hi);
      camera.target += 0.1f * (centre.cast<float>() - camera.target);
      if (follow_zoom) {
        follow_extent = follow_extent.cwiseMax(hi - lo);
        const Vec3 half = 0.5 * follow_extent;
        const float close = frame_box((centre - half).cast<float>(), (centre + half).cast<float>(),
                                      aspect(), camera.yaw_degrees, camera.pitch_degrees)
                                .distance;
        camera.distance += 0.03f * (close - camera.distance);
      }
    }
    const auto draw_start = Clock::now();
    const double draw_cpu_start = thread_cpu_seconds();
    target->resize(fb_width, fb_height);
    target->bind();
    renderer->draw(scene, camera, fb_width, fb_height);
    target->set_fxaa_rect(renderer->edge_rect());
    target->resolve();
    target->blit_to(0);
    if (options.stats) glFinish();
    const double drawn = seconds_since(draw_start);
    render_seconds = 0.9 * render_seconds + 0.1 * drawn;
    const double drawn_cpu = thread_cpu_seconds() - draw_cpu_start;
    if (frames_shown > 0) {  // the first frame builds the GPU buffers
      render_sum += drawn;
      render_cpu_sum += drawn_cpu;
      render_max = std::max(render_max, drawn);
      ++render_count;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    clipped_items.clear();
    panel_rect = PanelRect{};
    if (!options.hide_panel) panel();
    overlays();
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fb_width, fb_height);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    const bool last = options.frames >= 0 && frames_shown >= options.frames;
    if (last && !options.screenshot.empty()) save_screenshot(options.screenshot);
    if (screenshot_pending) {
      screenshot_pending = false;
      const std::string path = new_file_name(options.record_dir, ".png");
      try {
        save_screenshot(path);
        screenshot_path = path;
      } catch (const std::exception& e) {
        record_message = e.what();
      }
    }
    glfwSwapBuffers(window);
    if (frames_shown > 0) frame_cpu_sum += thread_cpu_seconds() - frame_cpu_start;
    ++frames_shown;
    if (last) glfwSetWindowShouldClose(window, GLFW_TRUE);
    return true;
  }

  void save_screenshot(const std::string& path) {
    std::vector<std::uint8_t> rows(static_cast<size_t>(fb_width) * fb_height * 3);
    std::vector<std::uint8_t> image(rows.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, fb_width, fb_height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
    const size_t row = static_cast<size_t>(fb_width) * 3;
    for (int y = 0; y < fb_height; ++y)
      std::copy_n(rows.data() + row * static_cast<size_t>(fb_height - 1 - y), row,
                  image.data() + row * static_cast<size_t>(y));
    write_png(path, fb_width, fb_height, image.data());
  }

  void print_stats() const {
    const double wall = seconds_since(start);
    std::printf("frames: %ld in %.2f s of wall time (%.1f frames/s)\n", frames_shown, wall,
                static_cast<double>(frames_shown) / wall);
    if (render_count > 0) {
      const double n = static_cast<double>(render_count);
      std::printf(
          "render: %.2f ms per frame (wall; %.2f at most), %.2f ms CPU of the window's "
          "thread (%ld frames, %dx%d, %d samples)\n",
          1e3 * render_sum / n, 1e3 * render_max, 1e3 * render_cpu_sum / n, render_count, fb_width,
          fb_height, target->samples());
      std::printf("frame: %.2f ms CPU of the window's thread (events, drawing, panel, swap)\n",
                  1e3 * frame_cpu_sum / n);
    }
    if (live && sim_samples > 0) {
      const double n = static_cast<double>(sim_samples);
      std::printf(
          "simulation: %.0f steps/s, %.3f simulated s per wall s, %.3f ms per step "
          "(wall), %.3f ms CPU per step (its thread)\n",
          sim_steps_per_second_sum / n, sim_rate_sum / n, sim_step_ms_sum / n,
          sim_step_cpu_ms_sum / n);
    }
    std::fflush(stdout);
  }
};

ViewerWindow::ViewerWindow(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ViewerWindow::~ViewerWindow() = default;

std::unique_ptr<ViewerWindow> ViewerWindow::live(const Scene& scene, const std::string& path,
                                                 const ViewOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  if (!options.screenshot.empty()) impl->options.lockstep = true;
  impl->open("jelly view - " + path);
  impl->init_live(scene, path);
  return std::unique_ptr<ViewerWindow>(new ViewerWindow(std::move(impl)));
}

std::unique_ptr<ViewerWindow> ViewerWindow::replay(const std::string& path,
                                                   const ViewOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  RecordingView probe(path);  // a bad file fails before a window opens
  const int frames = probe.recording().frames();
  require(options.start_frame >= 0 && options.start_frame < frames, "--frame", options.start_frame,
          "a recorded frame, 0 to " + std::to_string(frames - 1) + " (the recording holds " +
              std::to_string(frames) + " frames)");
  impl->open("jelly view - " + path);
  impl->init_replay(path);
  return std::unique_ptr<ViewerWindow>(new ViewerWindow(std::move(impl)));
}

int ViewerWindow::run() {
  while (frame()) {
  }
  if (impl_->options.stats) impl_->print_stats();
  return 0;
}

bool ViewerWindow::frame() { return impl_->frame(); }
void ViewerWindow::mouse_button(int button, bool press, double x, double y, int mods) {
  impl_->mouse_button(button, press, x, y, mods);
}
void ViewerWindow::cursor(double x, double y) { impl_->cursor(x, y); }
void ViewerWindow::scroll(double dy) { impl_->scroll(dy); }
void ViewerWindow::key(int glfw_key) { impl_->key(glfw_key); }
void ViewerWindow::toggle_recording() { impl_->toggle_recording(); }
std::string ViewerWindow::recording_path() const { return impl_->record_path; }
std::string ViewerWindow::last_screenshot() const { return impl_->screenshot_path; }
std::string ViewerWindow::recording_error() const {
  if (impl_->live && !impl_->live->front().recording_error.empty())
    return impl_->live->front().recording_error;
  return impl_->record_message;
}
void ViewerWindow::request_close() { glfwSetWindowShouldClose(impl_->window, GLFW_TRUE); }
Camera& ViewerWindow::camera() { return impl_->camera; }
int ViewerWindow::width() const { return impl_->fb_width; }
int ViewerWindow::height() const { return impl_->fb_height; }
const VecX& ViewerWindow::positions() const { return impl_->positions; }
int ViewerWindow::dragged_particle() const { return impl_->drag_particle; }
LiveSimulation* ViewerWindow::simulation() { return impl_->live.get(); }
void ViewerWindow::save_screenshot(const std::string& path) { impl_->save_screenshot(path); }
PanelRect ViewerWindow::panel_rect() const { return impl_->panel_rect; }
std::optional<PanelRect> ViewerWindow::banner_rect() const { return impl_->banner_rect; }
const std::vector<std::string>& ViewerWindow::clipped_panel_items() const {
  return impl_->clipped_items;
}

}  // namespace jelly::viewer
