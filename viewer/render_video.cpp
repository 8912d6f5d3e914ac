#include <jelly/viewer/render_video.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/viewer/offscreen.hpp>
#include <jelly/viewer/recording_view.hpp>
#include <jelly/viewer/render_target.hpp>
#include <jelly/viewer/renderer.hpp>
#include <jelly/viewer/video_writer.hpp>

namespace jelly::viewer {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

RenderVideoReport render_video(const std::string& recording_path, const std::string& output,
                               const RenderVideoOptions& options) {
  const auto start = Clock::now();
  require(options.width > 0 && options.width <= 8192, "--width", options.width, "1 to 8192 pixels");
  require(options.height > 0 && options.height <= 8192, "--height", options.height,
          "1 to 8192 pixels");
  require(options.samples >= 1 && options.samples <= 16, "--samples", options.samples, "1 to 16");
  // NaN compares false with everything: it would have meant "the recording's start" silently.
  require(std::isfinite(options.start), "--start", options.start, "a finite time in seconds");
  require(std::isfinite(options.end), "--end", options.end, "a finite time in seconds");
  video_format(output);
  const RecordingView view(recording_path);
  const double fps = options.fps > 0 ? options.fps : view.native_fps();
  const auto& time = view.recording().time;
  const std::vector<int> frames =
      view.video_frames(fps, options.start >= 0 ? options.start : time.front(),
                        options.end >= 0 ? options.end : time.back());
  // Without --camera the camera follows the bodies (RecordingView::Follow).
  const float aspect = static_cast<float>(options.width) / static_cast<float>(options.height);
  const RecordingView::Follow follow(view, frames, aspect);
  Camera camera = follow.at(frames.front());
  if (!options.camera.empty()) camera.parse(options.camera);

  VideoWriter writer(output, options.width, options.height, fps, options.crf);
  OffscreenContext context;
  RenderVideoReport report;
  report.renderer = context.description();
  RenderOptions render_options;
  render_options.shadows = options.shadows;
  Renderer renderer(render_options);
  RenderTarget target(options.width, options.height, options.samples, options.fxaa);
  RenderScene scene = view.make_scene(frames.front());
  scene.show_particles = scene.show_particles || options.particles;
  scene.show_springs = options.springs;
  std::vector<std::uint8_t> pixels;
  for (const int k : frames) {
    auto t = Clock::now();
    view.update(k, scene);
    if (options.camera.empty()) camera = follow.at(k);
    target.bind();
    renderer.draw(scene, camera, options.width, options.height);
    target.set_fxaa_rect(renderer.edge_rect());
    target.resolve();
    target.read_rgb(pixels);
    report.render_seconds += seconds_since(t);
    t = Clock::now();
    writer.write(pixels.data());
    report.encode_seconds += seconds_since(t);
  }
  const auto t = Clock::now();
  writer.close();
  report.encode_seconds += seconds_since(t);
  report.frames = writer.frames();
  report.seconds = seconds_since(start);
  return report;
}

}  // namespace jelly::viewer
