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

#include <jelly/core/model.hpp>
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
  // One unit normal per vertex, written as "vn" and the faces as "f a//a b//b c//c"; empty:
  // none (faces "f a b c").
  std::vector<Vec3> normals;
};

// Area-weighted vertex normals into `normals` (resized to the vertex count): per vertex the
// normalized sum of (b - a) x (c - a) over its triangles a-b-c, i.e. of each triangle's unit
// normal times twice its area. They point to the side from which the triangles are
// counter-clockwise (outward for the project's surfaces). A vertex in no triangle, or whose sum
// vanishes, gets +y, so every normal is a unit vector.
void vertex_normals(const std::vector<Vec3>& vertices, const std::vector<Triangle>& triangles,
                    std::vector<Vec3>& normals);

// A rigid mesh (a terrain's, an obstacle's) with normals that keep its edges sharp: a corner of a
// triangle takes the area-weighted mean of the face normals around its vertex that are within
// `crease_degrees` of its own face's, and a vertex is split into one copy per distinct normal.
// A box gets flat faces, a sphere stays smooth. Triangles keep their order and winding.
ObjObject crease_normals(const std::string& name, const std::vector<Vec3>& vertices,
                         const std::vector<Triangle>& triangles, double crease_degrees = 45);

// Writes the objects into one OBJ file ("o name", "v x y z" with 9 significant digits, "vn" when
// an object has normals, "f a b c" or "f a//a b//b c//c" with indices counted over the whole
// file). With `one_object` given, they are groups ("g
// name") of one object of that name instead: a tool then imports one mesh with every vertex
// in order (what a point cache over all of them needs). The file is written beside and renamed:
// a failed write leaves an existing file as it was. Throws InputError when its folder is missing
// or not writable, std::runtime_error naming the path when the write fails.
void write_obj(const std::string& path, const std::vector<ObjObject>& objects,
               const std::string& one_object = "");
// The text write_obj writes.
std::string obj_text(const std::vector<ObjObject>& objects, const std::string& one_object = "");

// Reads back what write_obj wrote: one ObjObject per object or group, vertices, normals and
// triangles in order (a face's normal indices must equal its vertex indices, as write_obj writes
// them; other OBJ statements are skipped). Throws InputError for a file it cannot read.
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
