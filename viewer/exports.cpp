#include <jelly/viewer/detail/exports.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <utility>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/viewer/scene_builder.hpp>

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
    vertex_normals(o.vertices, o.triangles, o.normals);
    objects.push_back(std::move(o));
  }
  return objects;
}

std::vector<ExportTerrain> export_terrains(const Recording& recording) {
  const Terrains terrains = recording_terrains(recording);
  std::vector<ExportTerrain> out;
  if (terrains.empty()) return out;
  Vec3 lo, hi;
  if (recording.position.empty())
    bounds_of(recording.model.rest_position, lo, hi);
  else
    bounds_of(recording.position, lo, hi);
  const bool any = lo.x() <= hi.x();
  const Vec3 centre = any ? Vec3(0.5 * (lo + hi)) : Vec3::Zero();
  const Real extent = 0.6 * (any ? (hi - lo).norm() : 0.0) + 1.0;
  const std::vector<Real> times = recording.time.empty() ? std::vector<Real>{0.0} : recording.time;
  for (size_t i = 0; i < terrains.size(); ++i) {
    const Terrain& terrain = *terrains[i];
    const TriangleMesh mesh = terrain_mesh(terrain, centre, extent);
    ExportTerrain e;
    e.mesh = crease_normals(std::to_string(i) + "_" + std::string(terrain.kind()), mesh.vertices,
                            mesh.triangles);
    for (Real t : times) {
      e.poses.push_back(terrain_pose(terrain, t));
      e.moves = e.moves || !e.poses.back().isApprox(e.poses.front(), 1e-12);
    }
    out.push_back(std::move(e));
  }
  return out;
}

namespace {

// The terrain's mesh placed at `pose`: world coordinates, normals rotated along.
ObjObject placed_terrain(const ExportTerrain& terrain, const Eigen::Isometry3d& pose) {
  ObjObject o = terrain.mesh;
  for (Vec3& v : o.vertices) v = pose * v;
  for (Vec3& n : o.normals) n = (pose.linear() * n).normalized();
  return o;
}

}  // namespace

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
  std::vector<jelly::detail::FileReplacement> files;
  files.reserve(static_cast<size_t>(recording.frames()));
  for (int k = 0; k < recording.frames(); ++k) {
    files.emplace_back((std::filesystem::path(dir) / obj_sequence_name(k)).string());
    files.back().write(obj_text(surface_objects(surfaces, recording.position[k])));
  }
  for (const ExportTerrain& terrain : export_terrains(recording)) {
    const std::string stem = "terrain_" + terrain.mesh.name;
    const int count = terrain.moves ? static_cast<int>(terrain.poses.size()) : 1;
    for (int k = 0; k < count; ++k) {
      char suffix[32];
      std::snprintf(suffix, sizeof suffix, "_%04d", k);
      files.emplace_back(
          (std::filesystem::path(dir) / (stem + (terrain.moves ? suffix : "") + ".obj")).string());
      files.back().write(
          obj_text({placed_terrain(terrain, terrain.poses[static_cast<size_t>(k)])}));
    }
  }
  // The earlier sequence's frames past this one's last, found before the renames.
  std::vector<std::string> stale;
  if (replace) {
    for (const std::string& f : obj_sequence_files(dir)) {
      const std::string name = std::filesystem::path(f).filename().string();
      if (std::stol(name.substr(6, name.size() - 10)) >= recording.frames()) stale.push_back(f);
    }
  }
  for (jelly::detail::FileReplacement& file : files) file.commit();
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
  // Without normals: a tool keeps imported normals as they are while the cache moves the
  // vertices (Blender's custom normals), so they would be the rest pose's in every frame.
  std::vector<ObjObject> rest_objects = surface_objects(surfaces, recording.model.rest_position);
  for (ObjObject& o : rest_objects) o.normals.clear();
  jelly::detail::FileReplacement rest(obj_path);
  rest.write(obj_text(rest_objects, std::filesystem::path(pc2_path).stem().string()));
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
