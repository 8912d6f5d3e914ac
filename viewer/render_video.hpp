#pragma once
// `jelly render`: a recording drawn offscreen (EGL, no display) by the same Renderer as the
// window, frame by frame, into a video (VideoWriter: ffmpeg for .mp4 and .gif, or PNG frames).
#include <string>

namespace jelly::viewer {

struct RenderVideoOptions {
  int width = 1280, height = 720;
  double fps = 0;               // video frames per simulated second; 0 = the recording's own rate
  double start = -1, end = -1;  // simulated time range; < 0 = the recording's
  std::string camera;           // "yaw,pitch,distance[,tx,ty,tz]"; empty = framed like `jelly view`
  int samples = 4;
  bool fxaa = false;  // FXAA after single-sampled drawing, in place of multisampling
  bool particles = false, springs = false, shadows = true;
  int crf = 18;  // H.264 quality (lower is better)
};

struct RenderVideoReport {
  int frames = 0;
  double seconds = 0;         // wall time in all
  double render_seconds = 0;  // drawing and reading back the pixels
  double encode_seconds = 0;  // handing the frames to the writer (ffmpeg or PNG)
  std::string renderer;       // the OpenGL renderer and how the context was made
};

// Throws InputError for a bad file or option, std::runtime_error when EGL or ffmpeg fails.
RenderVideoReport render_video(const std::string& recording_path, const std::string& output,
                               const RenderVideoOptions& options);

}  // namespace jelly::viewer
