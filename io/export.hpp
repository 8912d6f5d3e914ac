#pragma once
// File formats that DCC tools read: Wavefront OBJ triangle meshes and PC2 point caches (the
// format of Blender's Mesh Cache modifier, Houdini and 3ds Max: a header and float32 x, y, z
// per point per sample). Writers only; they know nothing of bodies or recordings.
#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

namespace detail {
class FileReplacement;
}

// One named object of an OBJ file.
struct ObjObject {
  std::string name;
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // 0-based here, written 1-based
};

// Writes the objects into one OBJ file ("o name", "v x y z" with 9 significant digits, "f a b c"
// with indices counted over the whole file). With `one_object` given, they are groups ("g
// name") of one object of that name instead: a tool then imports one mesh with every vertex
// in order (what a point cache over all of them needs). The file is written beside and renamed:
// a failed write leaves an existing file as it was. Throws InputError when its folder is missing
// or not writable, std::runtime_error naming the path when the write fails.
void write_obj(const std::string& path, const std::vector<ObjObject>& objects,
               const std::string& one_object = "");
// The text write_obj writes.
std::string obj_text(const std::vector<ObjObject>& objects, const std::string& one_object = "");

// Reads back what write_obj wrote: one ObjObject per object or group, vertices and triangles in
// order (other OBJ statements are skipped). Throws InputError for a file it cannot read.
std::vector<ObjObject> read_obj(const std::string& path);

// A PC2 file written sample by sample beside its path; close() fixes the sample count in the
// header and renames it onto the path. Destroyed without close(), or after a failed write, it
// leaves an existing file at the path as it was.
class Pc2Writer {
 public:
  // start_frame: the frame of the first sample; sample_rate: frames between samples.
  // Throws InputError when the path's folder is missing or not writable, std::runtime_error
  // naming the path for other failures.
  Pc2Writer(const std::string& path, int num_points, float start_frame = 0, float sample_rate = 1);
  ~Pc2Writer();
  Pc2Writer(const Pc2Writer&) = delete;
  Pc2Writer& operator=(const Pc2Writer&) = delete;

  // One sample: num_points points, [3 num_points] values.
  void write(const double* xyz);
  // Writes the sample count, closes and renames; throws std::runtime_error when the file could
  // not be written.
  void close();
  int samples() const { return samples_; }

 private:
  std::string path_;
  std::unique_ptr<detail::FileReplacement> replacement_;
  std::FILE* file_ = nullptr;
  int samples_ = 0;
  std::vector<float> buffer_;
  bool failed_ = false;
};

// A PC2 file read back.
struct Pc2Data {
  int num_points = 0;
  float start_frame = 0, sample_rate = 1;
  std::vector<std::vector<float>> samples;  // [samples][3 num_points]
};
// Throws InputError for a file that is not PC2 or is truncated.
Pc2Data read_pc2(const std::string& path);

}  // namespace jelly
