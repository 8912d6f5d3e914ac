#include <jelly/viewer/recording_view.hpp>

#include <algorithm>
#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly::viewer {

RecordingView::RecordingView(const std::string& path) : recording_(read_recording(path)) {
  if (recording_.frames() == 0) throw InputError("recording", path, "a recording with frames");
  bounds_of(recording_.position, lo_, hi_);
  builder_ = std::make_unique<SceneBuilder>(recording_.model, recording_surfaces(recording_),
                                            recording_terrains(recording_), lo_, hi_);
}

int RecordingView::frame_at(Real t) const {
  const auto& time = recording_.time;
  const int after = static_cast<int>(std::lower_bound(time.begin(), time.end(), t) - time.begin());
  if (after >= frames()) return frames() - 1;
  if (after == 0) return 0;
  return t - time[after - 1] <= time[after] - t ? after - 1 : after;
}

double RecordingView::native_fps() const {
  const auto it = recording_.attributes.find("output_interval");
  if (it != recording_.attributes.end()) {
    const double interval = std::atof(it->second.c_str());
    if (interval > 0) return 1.0 / interval;
  }
  if (frames() >= 2) {
    const double span = recording_.time.back() - recording_.time.front();
    if (span > 0) return (frames() - 1) / span;
  }
  return 60;
}

std::vector<int> RecordingView::video_frames(double fps, Real t_start, Real t_end) const {
  const Real first = recording_.time.front(), last = recording_.time.back();
  t_start = std::clamp(t_start, first, last);
  t_end = std::clamp(t_end, t_start, last);
  std::vector<int> out;
  const long count = static_cast<long>(std::floor((t_end - t_start) * fps + 1e-6)) + 1;
  for (long k = 0; k < count; ++k) out.push_back(frame_at(t_start + static_cast<Real>(k) / fps));
  return out;
}

RenderScene RecordingView::make_scene(int k) const {
  return builder_->make_scene(recording_.position[k], recording_.time[k]);
}

void RecordingView::update(int k, RenderScene& scene) const {
  builder_->update(recording_.position[k], recording_.time[k], scene);
}

namespace {

// The frames a camera's sight lines are checked at: at most eight, evenly through `frames`.
std::vector<int> sight_frames(const std::vector<int>& frames) {
  std::vector<int> out;
  const size_t count = std::min<size_t>(8, frames.size());
  for (size_t i = 0; i < count; ++i)
    out.push_back(frames[i * (frames.size() - 1) / std::max<size_t>(count - 1, 1)]);
  return out;
}

}  // namespace

Camera RecordingView::default_camera(float aspect) const {
  std::vector<int> all(static_cast<size_t>(frames()));
  for (int k = 0; k < frames(); ++k) all[static_cast<size_t>(k)] = k;
  Sight sight;
  for (const int k : sight_frames(all))
    add_sight_points(recording_.position[static_cast<size_t>(k)], builder_->terrains(),
                     recording_.time[static_cast<size_t>(k)], 24, sight.points);
  return framing_camera(lo_, hi_, builder_->terrains(), recording_.time.front(), aspect, {sight});
}

RecordingView::Follow::Follow(const RecordingView& view, const std::vector<int>& frames,
                              float aspect)
    : view_(view) {
  const auto& position = view.recording().position;
  const int first = frames.empty() ? 0 : frames.front();
  Vec3 extent = Vec3::Zero();
  for (const int k : frames) {
    Vec3 lo, hi;
    bounds_of(position[static_cast<size_t>(k)], lo, hi);
    extent = extent.cwiseMax(hi - lo);
  }
  Vec3 lo, hi;
  bounds_of(position[static_cast<size_t>(first)], lo, hi);
  const Vec3 centre = 0.5 * (lo + hi);
  // The bodies seen where the camera will be at a few of the frames.
  std::vector<Sight> sights;
  for (const int k : sight_frames(frames)) {
    const VecX& x = position[static_cast<size_t>(k)];
    Vec3 a, b;
    bounds_of(x, a, b);
    Sight sight;
    sight.shift = (0.5 * (a + b) - centre).cast<float>();
    add_sight_points(x, view.builder().terrains(), view.recording().time[static_cast<size_t>(k)],
                     24, sight.points);
    sights.push_back(std::move(sight));
  }
  base_ = framing_camera(centre - 0.5 * extent, centre + 0.5 * extent, view.builder().terrains(),
                         view.recording().time[static_cast<size_t>(first)], aspect, sights, false);
  offset_ = base_.target - centre.cast<float>();
}

Camera RecordingView::Follow::at(int k) const {
  Vec3 lo, hi;
  bounds_of(view_.recording().position[static_cast<size_t>(k)], lo, hi);
  Camera camera = base_;
  camera.target = (0.5 * (lo + hi)).cast<float>() + offset_;
  return camera;
}

}  // namespace jelly::viewer
