#pragma once
// Writes rendered frames through an ffmpeg process fed raw RGB frames on a pipe (it encodes on
// another core while the next frame is drawn): .mp4 (H.264), .gif, or PNG images named by a
// printf pattern with one integer conversion ("frames/%04d.png": frame 0 is frames/0000.png).
#include <sys/types.h>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

namespace jelly::detail {
class FileReplacement;
}

namespace jelly::viewer {

enum class VideoFormat { kMp4, kGif, kPngSequence };

// The format a path asks for; throws InputError naming `field` for anything else (an .mp4 or
// .gif path, or a .png pattern with one %d conversion).
VideoFormat video_format(const std::string& path, const std::string& field = "--output");

// ffmpeg writes beside the path (out.partial-<pid>.mp4, frames/0000.partial-<pid>.png: it
// chooses the format from the name) and close() renames what it wrote onto the path once ffmpeg
// has finished without an error: a failed or abandoned video leaves existing files as they were.
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
  // Waits for ffmpeg to finish the file and renames it onto the path; throws std::runtime_error
  // when ffmpeg failed or the file could not be moved (nothing is renamed then).
  void close();
  int frames() const { return frames_; }

 private:
  // The name of frame k of a PNG pattern.
  static std::string frame_name(const std::string& pattern, int k);
  // Removes what ffmpeg wrote under the temporary names.
  void remove_temporaries();

  std::string path_;
  std::string ffmpeg_path_;  // the temporary name (or pattern) ffmpeg writes
  std::unique_ptr<detail::FileReplacement> replacement_;  // .mp4 and .gif
  VideoFormat format_;
  int width_, height_;
  int frames_ = 0;
  std::FILE* pipe_ = nullptr;
  pid_t pid_ = -1;
  std::thread errors_;      // reads ffmpeg's stderr into error_text_ until ffmpeg exits
  std::string error_text_;  // written by errors_ only until it is joined
};

}  // namespace jelly::viewer
