#pragma once
// Internal: a thin RAII layer over the HDF5 C API shared by the recorder and the readers. Not
// installed; HDF5 types stay out of jelly's public headers.
#include <hdf5.h>

#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly::h5 {

// The HDF5 library jelly links is not built thread-safe: every use of it in jelly holds this.
std::recursive_mutex& library_mutex();

// Turns off HDF5's printing of error stacks while alive (the errors become exceptions).
class QuietErrors {
 public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// The innermost messages of the current HDF5 error stack, e.g. "unable to open file: ...".
std::string error_text();
// Throws std::runtime_error "HDF5: <what>: <error_text()>" when id < 0.
hid_t check(hid_t id, const std::string& what);

// An owned HDF5 identifier, closed with the H5?close function that fits its kind.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  Handle(hid_t id, const std::string& what) : id_(check(id, what)) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, -1)) {}
  Handle& operator=(Handle&& other) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset();

 private:
  hid_t id_ = -1;
};

// Files. Both throw InputError naming the path and HDF5's reason. `exclusive`: fail when the
// file exists instead of truncating it.
Handle create_file(const std::string& path, bool exclusive = false);
Handle open_file(const std::string& path, bool writable = false);

Handle create_group(hid_t parent, const std::string& name);
Handle open_group(hid_t parent, const std::string& name);
Handle open_dataset(hid_t parent, const std::string& name);
bool exists(hid_t parent, const std::string& path);  // every link along the path exists
// The names of a group's members, in name order.
std::vector<std::string> member_names(hid_t group);
void hard_link(hid_t target_parent, const std::string& target, hid_t link_parent,
               const std::string& link);

// Attributes (replaced when they exist).
void write_attribute(hid_t object, const std::string& name, const std::string& value);
void write_attribute(hid_t object, const std::string& name, double value);
void write_attribute(hid_t object, const std::string& name, long value);
void write_attribute(hid_t object, const std::string& name, const std::vector<double>& value);
void write_attribute(hid_t object, const std::string& name, const std::vector<int>& value);
bool has_attribute(hid_t object, const std::string& name);
std::string read_string_attribute(hid_t object, const std::string& name);
double read_double_attribute(hid_t object, const std::string& name);
long read_long_attribute(hid_t object, const std::string& name);
// Every attribute of an object as text (numbers with full precision, arrays space-separated).
std::vector<std::pair<std::string, std::string>> read_attributes_as_text(hid_t object);

// A fixed-size dataset written in one go: type is a file type (H5T_IEEE_F64LE, H5T_STD_I32LE,
// H5T_STD_I64LE); data is in the matching native type.
void write_dataset(hid_t parent, const std::string& name, hid_t file_type, hid_t memory_type,
                   const std::vector<hsize_t>& dims, const void* data);
inline void write_dataset(hid_t parent, const std::string& name, const std::vector<hsize_t>& dims,
                          const double* data) {
  write_dataset(parent, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, data);
}
inline void write_dataset(hid_t parent, const std::string& name, const std::vector<hsize_t>& dims,
                          const int* data) {
  write_dataset(parent, name, H5T_STD_I32LE, H5T_NATIVE_INT, dims, data);
}

std::vector<hsize_t> dataset_dims(hid_t dataset);
// The readers refuse a dataset larger than this, or than its stored bytes could hold (a damaged
// file can claim any shape).
constexpr hsize_t kMaxReadBytes = hsize_t{16} << 30;
// What a reader does when a time series does not read whole: throw (kAll), or keep the frames
// before the first that does not read (kLeadingReadable: a run killed while HDF5 wrote a chunk
// can leave the last frames named in the file's index but not stored).
enum class Frames { kAll, kLeadingReadable };
// The whole dataset converted to double / int / long; dims receives its shape. Throws
// std::runtime_error for a missing dataset or one of more than kMaxReadBytes (or than it stores).
std::vector<double> read_doubles(hid_t parent, const std::string& name,
                                 std::vector<hsize_t>* dims = nullptr,
                                 Frames frames = Frames::kAll);
std::vector<int> read_ints(hid_t parent, const std::string& name,
                           std::vector<hsize_t>* dims = nullptr);
std::vector<long> read_longs(hid_t parent, const std::string& name,
                             std::vector<hsize_t>* dims = nullptr, Frames frames = Frames::kAll);

// A dataset [T][shape...] that grows along its first (time) axis: chunked along time, optionally
// shuffled and deflate-compressed. The handle stays open; append() extends and writes a block of
// whole frames.
class Series {
 public:
  Series() = default;
  Series(hid_t parent, const std::string& name, hid_t file_type, hid_t memory_type,
         std::vector<hsize_t> frame_shape, hsize_t chunk_frames, int compression_level);
  // Writes `frames` frames stored contiguously at data, after those already written.
  void append(const void* data, hsize_t frames);
  hsize_t size() const { return frames_; }
  hid_t id() const { return dataset_.get(); }

 private:
  Handle dataset_;
  hid_t memory_type_ = -1;
  std::vector<hsize_t> frame_shape_;
  hsize_t frames_ = 0;
};

}  // namespace jelly::h5
