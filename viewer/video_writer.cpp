#include <jelly/viewer/video_writer.hpp>

#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <regex>
#include <stdexcept>
#include <vector>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>

extern char** environ;

namespace jelly::viewer {

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

VideoFormat video_format(const std::string& path, const std::string& field) {
  if (ends_with(path, ".mp4")) return VideoFormat::kMp4;
  if (ends_with(path, ".gif")) return VideoFormat::kGif;
  // One %d, %0Nd or %Nd and no other conversion ("%%" is a literal percent sign).
  static const std::regex pattern(R"(^([^%]|%%)*%0?[0-9]*d([^%]|%%)*\.png$)");
  if (std::regex_match(path, pattern)) return VideoFormat::kPngSequence;
  throw InputError(field, path,
                   "an .mp4 or .gif file, or PNG frames named by a pattern with one %d "
                   "(e.g. frames/%04d.png)");
}

VideoWriter::VideoWriter(const std::string& path, int width, int height, double fps, int crf)
    : path_(path), format_(video_format(path)), width_(width), height_(height) {
  require(width > 0 && height > 0, "size", std::to_string(width) + "x" + std::to_string(height),
          "a positive width and height");
  require(fps > 0 && fps <= 1000, "--fps", fps, "frames per second in (0, 1000]");
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder))
    throw InputError("--output", path,
                     "a path in an existing folder ('" + folder.string() + "' does not exist)");
  if (format_ == VideoFormat::kMp4)
    require(width % 2 == 0 && height % 2 == 0, "--width/--height",
            std::to_string(width) + "x" + std::to_string(height),
            "an even width and height for H.264 (.mp4)");

  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  const std::string rate = to_text(fps);
  std::vector<std::string> args = {
      "ffmpeg",   "-hide_banner", "-loglevel", "error", "-nostdin",   "-y", "-f", "rawvideo",
      "-pix_fmt", "rgb24",        "-s",        size,    "-framerate", rate, "-i", "pipe:0"};
  if (format_ == VideoFormat::kMp4) {
    for (const char* a : {"-c:v", "libx264", "-preset", "superfast", "-crf"}) args.emplace_back(a);
    args.push_back(std::to_string(crf));
    for (const char* a : {"-pix_fmt", "yuv420p", "-movflags", "+faststart"}) args.emplace_back(a);
  } else if (format_ == VideoFormat::kPngSequence) {
    for (const char* a : {"-f", "image2", "-start_number", "0", "-c:v", "png"})
      args.emplace_back(a);
  } else {
    args.emplace_back("-vf");
    args.emplace_back(
        "split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse=dither=bayer:"
        "bayer_scale=4");
  }
  if (format_ == VideoFormat::kPngSequence) {
    ffmpeg_path_ = jelly::detail::FileReplacement::temporary_name(
        path, jelly::detail::FileReplacement::Name::kBeforeExtension);
  } else {
    replacement_ = std::make_unique<jelly::detail::FileReplacement>(
        path, jelly::detail::FileReplacement::Name::kBeforeExtension);
    ffmpeg_path_ = replacement_->temporary();
  }
  args.push_back(ffmpeg_path_);

  int fds[2], errors[2];
  if (pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  if (pipe(errors) != 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, errors[1], STDERR_FILENO);
  for (int fd : {fds[0], fds[1], errors[0], errors[1]}) {
    posix_spawn_file_actions_addclose(&actions, fd);
  }
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int spawned = posix_spawnp(&pid_, "ffmpeg", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  ::close(errors[1]);
  if (spawned != 0) {
    ::close(fds[1]);
    ::close(errors[0]);
    pid_ = -1;
    throw std::runtime_error(std::string("cannot run ffmpeg (") + std::strerror(spawned) +
                             "): install it (apt-get install ffmpeg)");
  }
  // ffmpeg runs with -loglevel error: what it prints is an error. Some it does not count in its
  // exit status (the GIF muxer's "Error writing trailer" on a full disk exits 0), so the text
  // decides too; read on a thread so that a long message cannot block ffmpeg.
  errors_ = std::thread([this, fd = errors[0]] {
    char buffer[4096];
    for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) != 0;) {
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) break;
      error_text_.append(buffer, static_cast<size_t>(n));
    }
    ::close(fd);
  });
  pipe_ = fdopen(fds[1], "wb");
  // A dead ffmpeg makes writes fail with EPIPE instead of killing this process.
  std::signal(SIGPIPE, SIG_IGN);
}

VideoWriter::~VideoWriter() {
  // Not closed: ffmpeg is ended and what it wrote is removed; existing files stay as they were.
  if (pipe_ != nullptr) {
    std::fclose(pipe_);
    pipe_ = nullptr;
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }
  if (errors_.joinable()) errors_.join();
  remove_temporaries();
}

std::string VideoWriter::frame_name(const std::string& pattern, int k) {
  std::vector<char> name(pattern.size() + 32);
  std::snprintf(name.data(), name.size(), pattern.c_str(), k);
  return name.data();
}

void VideoWriter::remove_temporaries() {
  if (replacement_) replacement_->discard();
  if (format_ == VideoFormat::kPngSequence) {
    // ffmpeg writes at most one file per frame it was given.
    for (int k = 0; k <= frames_; ++k) std::remove(frame_name(ffmpeg_path_, k).c_str());
  }
}

void VideoWriter::write(const std::uint8_t* rgb) {
  const size_t bytes = static_cast<size_t>(width_) * height_ * 3;
  if (pipe_ == nullptr) throw std::runtime_error("the video '" + path_ + "' is closed");
  if (std::fwrite(rgb, 1, bytes, pipe_) != bytes)
    throw std::runtime_error("ffmpeg stopped while writing '" + path_ + "' (" +
                             std::strerror(errno) + ")");
  ++frames_;
}

void VideoWriter::close() {
  if (pipe_ == nullptr) return;
  std::fclose(pipe_);
  pipe_ = nullptr;
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (errors_.joinable()) errors_.join();  // ffmpeg has exited: its end of the pipe is closed
  while (!error_text_.empty() && error_text_.back() == '\n') error_text_.pop_back();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !error_text_.empty()) {
    remove_temporaries();
    throw std::runtime_error("ffmpeg failed to write '" + path_ + "' (exit status " +
                             std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
                             (error_text_.empty() ? "" : ": " + error_text_) +
                             "); existing files were left as they were");
  }
  if (replacement_) {
    struct stat info {};
    if (frames_ > 0 && (stat(ffmpeg_path_.c_str(), &info) != 0 || info.st_size == 0)) {
      remove_temporaries();
      throw std::runtime_error("ffmpeg wrote nothing to '" + path_ + "'");
    }
    replacement_->commit();
    return;
  }
  // A PNG sequence: every frame's file must be there before any is renamed.
  std::vector<jelly::detail::FileReplacement> files;
  for (int k = 0; k < frames_; ++k) {
    files.push_back(
        jelly::detail::FileReplacement::adopt(frame_name(path_, k), frame_name(ffmpeg_path_, k)));
  }
  for (int k = 0; k < frames_; ++k) {
    struct stat info {};
    if (stat(files[k].temporary().c_str(), &info) != 0 || info.st_size == 0) {
      remove_temporaries();
      throw std::runtime_error("ffmpeg did not write frame " + std::to_string(k) + " of '" + path_ +
                               "'");
    }
  }
  for (jelly::detail::FileReplacement& file : files) file.commit();
}

}  // namespace jelly::viewer
