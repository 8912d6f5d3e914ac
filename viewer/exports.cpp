#include <jelly/viewer/exports.hpp>

#include <cstdio>
#include <filesystem>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>

namespace jelly::viewer {

namespace {

std::vector<BodySurface> surfaces_of(const Recording& recording) {
  std::vector<BodySurface> surfaces = recording_surfaces(recording);
  int triangles = 0;
  for (const BodySurface& s : surfaces) triangles += static_cast<int>(s.triangles.size());
  if (triangles == 0)
    throw InputError("recording", std::to_string(recording.model.num_particles()) + " particles",
                     "bodies with a render surface");
  return surfaces;
}

}  // namespace

std::vector<ObjObject> surface_objects(const std::vector<BodySurface>& surfaces, const VecX& x) {
  std::vector<ObjObject> objects;
  for (const BodySurface& s : surfaces) {
    ObjObject o;
    o.name = s.name;
    o.triangles = s.triangles;
    o.vertices.reserve(static_cast<size_t>(s.num_vertices()));
    for (int v = 0; v < s.num_vertices(); ++v) o.vertices.push_back(s.vertex(x, v));
    objects.push_back(std::move(o));
  }
  return objects;
}

int export_obj_sequence(const Recording& recording, const std::string& dir) {
  const std::vector<BodySurface> surfaces = surfaces_of(recording);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (!std::filesystem::is_directory(dir))
    throw InputError("--obj-sequence", dir, "a folder that can be created");
  // Every frame is written beside its file first and the files are renamed only when all are
  // written: a failed write (a full disk) leaves an earlier sequence in the folder as it was.
  std::vector<detail::FileReplacement> files;
  files.reserve(static_cast<size_t>(recording.frames()));
  for (int k = 0; k < recording.frames(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.obj", k);
    files.emplace_back((std::filesystem::path(dir) / name).string());
    files.back().write(obj_text(surface_objects(surfaces, recording.position[k])));
  }
  for (detail::FileReplacement& file : files) file.commit();
  return recording.frames();
}

std::string export_pc2(const Recording& recording, const std::string& pc2_path) {
  const std::vector<BodySurface> surfaces = surfaces_of(recording);
  int points = 0;
  for (const BodySurface& s : surfaces) points += s.num_vertices();
  const std::string obj_path = std::filesystem::path(pc2_path).replace_extension(".obj").string();
  if (obj_path == pc2_path)
    throw InputError("--pc2", pc2_path, "a path whose extension is not .obj (e.g. out.pc2)");
  // One object (the bodies as its groups): Blender's importer then makes one mesh of every
  // vertex in the cache's order.
  // Both files are written beside their paths; the rest surface is renamed after the cache.
  detail::FileReplacement rest(obj_path);
  rest.write(obj_text(surface_objects(surfaces, recording.model.rest_position),
                      std::filesystem::path(pc2_path).stem().string()));
  Pc2Writer pc2(pc2_path, points, 0, 1);
  std::vector<double> xyz(static_cast<size_t>(3 * points));
  for (int k = 0; k < recording.frames(); ++k) {
    double* out = xyz.data();
    for (const BodySurface& s : surfaces) {
      s.vertices(recording.position[k], out);
      out += 3 * s.num_vertices();
    }
    pc2.write(xyz.data());
  }
  pc2.close();
  rest.commit();
  return obj_path;
}

}  // namespace jelly::viewer
