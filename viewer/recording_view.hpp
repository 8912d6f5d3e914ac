#pragma once
// A recording ready to draw: its frames, the RenderScene builder for its model and terrains, the
// bounds of its whole motion and the camera that frames it. `jelly view FILE.h5` and `jelly
// render` both use it, so they show the same pictures.
#include <memory>
#include <string>
#include <vector>

#include <jelly/io/recording.hpp>
#include <jelly/viewer/camera.hpp>
#include <jelly/viewer/framing.hpp>
#include <jelly/viewer/scene_builder.hpp>

namespace jelly::viewer {

class RecordingView {
 public:
  // Throws InputError for a file that is not a jelly recording or holds no frames.
  explicit RecordingView(const std::string& path);

  const Recording& recording() const { return recording_; }
  const SceneBuilder& builder() const { return *builder_; }
  int frames() const { return recording_.frames(); }
  // The frame nearest time t (frames are recorded at the first step at or after each output
  // time, so not exactly at multiples of the interval).
  int frame_at(Real t) const;
  // The frames of a video at `fps` frames per second of simulated time (each the frame_at its
  // time), from t_start to t_end (clamped to the recording).
  std::vector<int> video_frames(double fps, Real t_start, Real t_end) const;
  // The recording's own frame rate (1 / its output interval), 60 when unknown.
  double native_fps() const;

  // A scene at frame k, and refreshing one to frame k.
  RenderScene make_scene(int k) const;
  void update(int k, RenderScene& scene) const;

  // The camera that shows the whole motion in an image of this aspect ratio.
  Camera default_camera(float aspect) const;
  // A camera that follows the bodies over `frames` (a video's): follow_camera(k) frames the
  // bodies at frame k at the size of their largest extent over `frames`, from the default
  // direction (not the ground below them: they fill more of the picture); its target moves with
  // the centre of their bounds, so they stay large.
  class Follow {
   public:
    Follow(const RecordingView& view, const std::vector<int>& frames, float aspect);
    Camera at(int k) const;

   private:
    const RecordingView& view_;
    Camera base_;
    Eigen::Vector3f offset_;  // base_.target minus the bodies' centre at the first frame
  };

 private:
  Recording recording_;
  std::unique_ptr<SceneBuilder> builder_;
  Vec3 lo_, hi_;
};

}  // namespace jelly::viewer
