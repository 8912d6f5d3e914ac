#pragma once
// `jelly export`: a recording's render surfaces (scene_adapter.hpp) and terrains as an OBJ per
// frame, as a PC2 point cache with the rest surface as OBJ beside it (io/detail/export.hpp writes
// the formats), or as one animated glTF 2.0 binary (.glb).
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <jelly/io/detail/export.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/viewer/scene_adapter.hpp>

namespace jelly::viewer {

// The surfaces of every body at positions x, one OBJ object per body, with area-weighted vertex
// normals (outward: io/detail/export.hpp vertex_normals).
std::vector<ObjObject> surface_objects(const std::vector<BodySurface>& surfaces, const VecX& x);

// A terrain of a recording as the exports give it: its mesh in its own frame with normals that
// keep its edges sharp (an infinite plane as a square around the bodies' motion over the whole
// run, half-size 0.6 x the diagonal of their bounding box + 1 m), and where it is at each frame.
struct ExportTerrain {
  ObjObject mesh;                        // named "<index>_<kind>", as /terrain/<name> in the file
  std::vector<Eigen::Isometry3d> poses;  // per recorded frame
  bool moves = false;                    // whether any pose differs from the first
};
// The terrains of the recording's scene (none for a recording without one).
std::vector<ExportTerrain> export_terrains(const Recording& recording);

// The name of frame k of an OBJ sequence: frame_0000.obj, frame_0001.obj, ... frame_12345.obj.
std::string obj_sequence_name(int frame);
// The files of DIR named as an OBJ sequence's frames (exactly as obj_sequence_name names them;
// regular files only), sorted by frame; empty when there are none or DIR is no folder.
std::vector<std::string> obj_sequence_files(const std::string& dir);

// Writes DIR/frame_0000.obj, DIR/frame_0001.obj, ... (one per recorded frame, the bodies; DIR is
// created) and the terrains beside them in world coordinates: DIR/terrain_<name>.obj for one
// that stays put, DIR/terrain_<name>_0000.obj, ... (one per frame) for one that moves. Returns
// the number of frame files. With `replace`, the frames of an earlier sequence past this one's
// last are then removed (only files named as frames: nothing else in DIR is touched), so that
// DIR holds this sequence's frames alone. Throws InputError for a recording without a surface or
// a folder that cannot be made.
int export_obj_sequence(const Recording& recording, const std::string& dir, bool replace = false);

// Writes the PC2 file (one sample per recorded frame, start frame 0, sample rate 1) and the
// rest surface (the surfaces at the model's rest positions, the vertex order of the cache) as
// an OBJ file of the same name with .obj, one object named after the file whose groups are the
// bodies; returns that OBJ's path.
std::string export_pc2(const Recording& recording, const std::string& pc2_path);

// Whether this jelly was built with tinygltf (export_gltf works).
bool gltf_available();
// Writes the recording as a glTF 2.0 binary file (.glb): per body a node whose mesh is its
// surface at frame 0 with normals and its colour as a PBR material (baseColorFactor: the sRGB
// colour converted to linear, as glTF wants it), with one morph target per later frame (position
// and normal displacements from frame 0) and an animation of the weights over the exact frame
// times (exact_frame_times), LINEAR, so frame k shows exactly target k and the time between two
// frames their linear blend. Per terrain a node with its mesh; a moving one with translation and
// rotation channels sampled at every frame. Throws InputError for a recording without a surface
// or a jelly built without tinygltf, std::runtime_error naming the path when the write fails.
void export_gltf(const Recording& recording, const std::string& path);

}  // namespace jelly::viewer
