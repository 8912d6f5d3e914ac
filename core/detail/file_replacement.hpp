#pragma once
// A file written beside its final path and renamed onto it only once complete, so that a write
// that fails (a full disk, a killed encoder) or a run that throws leaves the old file, or no file,
// exactly as it was, never half of a new one. Every writer of a user's output file goes through
// it (recordings, sidecars, scenes, meshes, exports, videos, screenshots). Internal; header-only.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <jelly/core/errors.hpp>

namespace jelly::detail {

// An advisory write lock (an open file description lock, fcntl F_OFD_SETLK: apart from HDF5's own
// flock) held on a file while it is written or replaced: a second writer that replaces the same
// file is refused instead of moving its file over one still being written. Only programs that
// ask for the lock see it.
class WriteLock {
 public:
  WriteLock() = default;
  // Locks `path` when it is an existing regular file that can be opened for writing (otherwise
  // holds nothing). Throws InputError naming the path when another writer holds the lock.
  explicit WriteLock(const std::string& path) {
    struct stat info {};
    if (stat(path.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) return;
    fd_ = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ < 0) return;
    struct flock lock {};
    lock.l_type = F_WRLCK;
    lock.l_whence = SEEK_SET;
    if (::fcntl(fd_, F_OFD_SETLK, &lock) != 0) {
      const int error = errno;
      release();
      if (error == EAGAIN || error == EACCES) {
        throw InputError("'" + path +
                         "' is being written by another run (it holds a write lock on it): "
                         "wait until it has finished, or choose another name");
      }
    }
  }
  WriteLock(WriteLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  WriteLock& operator=(WriteLock&& other) noexcept {
    if (this != &other) {
      release();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  WriteLock(const WriteLock&) = delete;
  WriteLock& operator=(const WriteLock&) = delete;
  ~WriteLock() { release(); }
  void release() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

class FileReplacement {
 public:
  // Where the temporary goes beside `path`: "<path>.partial-<pid>", or before the extension
  // ("out.partial-<pid>.mp4") for a writer that chooses its format from the name (ffmpeg).
  enum class Name { kAfterName, kBeforeExtension };

  // The temporary name for `path` (attempt > 0 appends "-<attempt>" to the tag).
  static std::string temporary_name(const std::string& path, Name name, int attempt = 0) {
    std::string tag = ".partial-" + std::to_string(static_cast<long>(getpid()));
    if (attempt > 0) tag += "-" + std::to_string(attempt);
    if (name == Name::kAfterName) return path + tag;
    const std::size_t slash = path.rfind('/');
    const std::size_t dot = path.rfind('.');
    const bool has_extension =
        dot != std::string::npos && dot > 0 && (slash == std::string::npos || dot > slash + 1);
    if (!has_extension) return path + tag;
    return path.substr(0, dot) + tag + path.substr(dot);
  }

  // Locks the file it replaces (WriteLock: InputError when another run writes it) and creates
  // the temporary, empty and exclusively (a name already taken, say by a killed run's
  // leftover, is never reused: the next attempt's name is tried). The writer then opens it for
  // writing (truncating). The file it replaces, if any, gives its permission bits at commit().
  // Throws, naming the path, its temporary and the system's reason, InputError when the folder
  // is missing or cannot be written, std::runtime_error for other failures (a full disk).
  explicit FileReplacement(std::string path, Name name = Name::kAfterName)
      : path_(std::move(path)) {
    struct stat old {};
    if (stat(path_.c_str(), &old) == 0) mode_ = static_cast<int>(old.st_mode & 07777);
    lock_ = WriteLock(path_);
    for (int attempt = 0;; ++attempt) {
      temporary_ = temporary_name(path_, name, attempt);
      // 0666 less the umask, as any new file; a replaced file's own bits are given at commit().
      const int fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd >= 0) {
        ::close(fd);
        break;
      }
      if (errno != EEXIST || attempt >= 100) {
        const int error = errno;
        const std::string message = "cannot write '" + path_ + "': cannot create its temporary '" +
                                    temporary_name(path_, name, attempt) + "' (" +
                                    std::strerror(error) + ")";
        temporary_.clear();
        // A folder that is missing, not a folder or not writable is the user's choice of path
        // (bad input); a full disk or an I/O error is a failed write.
        if (error == ENOENT || error == ENOTDIR || error == EACCES || error == EPERM ||
            error == EROFS || error == ENAMETOOLONG || error == ELOOP || error == EISDIR) {
          throw InputError(message);
        }
        throw std::runtime_error(message);
      }
    }
  }

  // Takes over `temporary`, already written (by another program: ffmpeg's frames), to move it
  // onto `path` on commit() or remove it.
  static FileReplacement adopt(std::string path, std::string temporary) {
    FileReplacement r;
    r.path_ = std::move(path);
    r.temporary_ = std::move(temporary);
    return r;
  }

  FileReplacement(FileReplacement&& other) noexcept
      : path_(std::move(other.path_)),
        temporary_(std::exchange(other.temporary_, {})),
        mode_(other.mode_),
        lock_(std::move(other.lock_)) {}
  FileReplacement& operator=(FileReplacement&& other) noexcept {
    if (this != &other) {
      discard();
      path_ = std::move(other.path_);
      temporary_ = std::exchange(other.temporary_, {});
      mode_ = other.mode_;
      lock_ = std::move(other.lock_);
    }
    return *this;
  }
  FileReplacement(const FileReplacement&) = delete;
  FileReplacement& operator=(const FileReplacement&) = delete;

  // An uncommitted temporary is removed: the old file stays as it was.
  ~FileReplacement() { discard(); }

  const std::string& path() const { return path_; }
  const std::string& temporary() const { return temporary_; }
  bool committed() const { return temporary_.empty(); }

  // Writes `bytes` as the temporary's whole content, every write checked. Throws
  // std::runtime_error naming path() and the reason.
  void write(std::string_view bytes) const {
    std::FILE* f = std::fopen(temporary_.c_str(), "wb");
    if (f == nullptr) {
      throw std::runtime_error("cannot write '" + path_ + "' (" + std::strerror(errno) + ")");
    }
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const int write_errno = errno;
    const bool closed = std::fclose(f) == 0;
    if (!written || !closed) {
      throw std::runtime_error("cannot write '" + path_ + "' (" +
                               std::strerror(written ? errno : write_errno) + ")");
    }
  }

  // Flushes the temporary to the disk (a write error the kernel kept until now is reported here)
  // and renames it onto path(). Throws std::runtime_error naming the file and the reason; the
  // temporary is then removed and the old file is as it was.
  void commit() {
    if (temporary_.empty()) return;
    const int fd = ::open(temporary_.c_str(), O_RDONLY | O_CLOEXEC);
    const bool synced = fd >= 0 && ::fsync(fd) == 0;
    const std::string sync_error = synced ? "" : std::strerror(errno);
    if (fd >= 0) ::close(fd);
    if (!synced) fail("cannot write '" + path_ + "' (" + sync_error + ")");
    if (mode_ >= 0) (void)::chmod(temporary_.c_str(), static_cast<mode_t>(mode_));
    if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
      fail("cannot move '" + temporary_ + "' onto '" + path_ + "' (" + std::strerror(errno) + ")");
    }
    temporary_.clear();
    lock_.release();
  }

  // Removes the temporary now (nothing when committed).
  void discard() noexcept {
    if (!temporary_.empty()) std::remove(temporary_.c_str());
    temporary_.clear();
    lock_.release();
  }

 private:
  FileReplacement() = default;
  [[noreturn]] void fail(const std::string& message) {
    discard();
    throw std::runtime_error(message);
  }

  std::string path_, temporary_;
  int mode_ = -1;   // the replaced file's permission bits, or -1
  WriteLock lock_;  // on the file replaced, until commit() or discard()
};

// Writes `bytes` to `path` through a FileReplacement, every write checked. Throws
// std::runtime_error naming the path and the reason; the old file is then as it was.
inline void replace_file(const std::string& path, std::string_view bytes) {
  FileReplacement replacement(path);
  replacement.write(bytes);
  replacement.commit();
}

}  // namespace jelly::detail
