#pragma once
// Writes rendered frames through an ffmpeg process fed raw RGB frames on a pipe (it encodes on
// another core while the next frame is drawn): .mp4 (H.264), .gif, or PNG images named by a
// printf pattern with one integer conversion ("frames/%04d.png": frame 0 is frames/0000.png).
#include <sys/types.h>
#include <cstdint>
#include <cstdio>
#include <string>

namespace jelly::viewer {

enum class VideoFormat { kMp4, kGif, kPngSequence };

// The format a path asks for; throws InputError naming `field` for anything else (an .mp4 or
// .gif path, or a .png pattern with one %d conversion).
VideoFormat video_format(const std::string& path, const std::string& field = "--output");

class VideoWriter {
 public:
  // Starts ffmpeg. Throws
  // InputError for a bad path or size (mp4 needs an even width and height) and
  // std::runtime_error when ffmpeg cannot be started.
  VideoWriter(const std::string& path, int width, int height, double fps, int crf = 18);
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // One frame of width x height RGB bytes, rows top to bottom. Throws std::runtime_error when
  // ffmpeg stopped.
  void write(const std::uint8_t* rgb);
  // Waits for ffmpeg to finish the file; throws std::runtime_error when it failed.
  void close();
  int frames() const { return frames_; }

 private:
  std::string path_;
  VideoFormat format_;
  int width_, height_;
  int frames_ = 0;
  std::FILE* pipe_ = nullptr;
  pid_t pid_ = -1;
};

}  // namespace jelly::viewer
