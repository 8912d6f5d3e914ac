#include <jelly/viewer/exports.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <utility>

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

std::string obj_sequence_name(int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d.obj", frame);
  return name;
}

std::vector<std::string> obj_sequence_files(const std::string& dir) {
  std::vector<std::pair<long, std::string>> frames;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    // frame_<at least 4 digits>.obj, the number written without other leading zeros.
    if (name.size() < 14 || name.size() > 20 || name.compare(0, 6, "frame_") != 0 ||
        name.compare(name.size() - 4, 4, ".obj") != 0)
      continue;
    const std::string digits = name.substr(6, name.size() - 10);
    if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const long frame = std::stol(digits);
    if (frame > std::numeric_limits<int>::max() ||
        obj_sequence_name(static_cast<int>(frame)) != name)
      continue;
    std::error_code status_error;
    if (!std::filesystem::is_regular_file(entry.symlink_status(status_error))) continue;
    frames.emplace_back(frame, entry.path().string());
  }
  std::sort(frames.begin(), frames.end());
  std::vector<std::string> files;
  for (auto& f : frames) files.push_back(std::move(f.second));
  return files;
}

int export_obj_sequence(const Recording& recording, const std::string& dir, bool replace) {
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
    files.emplace_back((std::filesystem::path(dir) / obj_sequence_name(k)).string());
    files.back().write(obj_text(surface_objects(surfaces, recording.position[k])));
  }
  // The earlier sequence's frames past this one's last, found before the renames.
  std::vector<std::string> stale;
  if (replace) {
    for (const std::string& f : obj_sequence_files(dir)) {
      const std::string name = std::filesystem::path(f).filename().string();
      if (std::stol(name.substr(6, name.size() - 10)) >= recording.frames()) stale.push_back(f);
    }
  }
  for (detail::FileReplacement& file : files) file.commit();
  for (const std::string& f : stale) {
    std::error_code remove_error;
    std::filesystem::remove(f, remove_error);
    if (remove_error)
      throw std::runtime_error("cannot remove " + f +
                               ", a frame of an earlier sequence: " + remove_error.message());
  }
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
