#pragma once
// `jelly export`: a recording's render surfaces (scene_adapter.hpp) as an OBJ per frame, or as a
// PC2 point cache with the rest surface as OBJ beside it (io/export.hpp writes the formats).
#include <string>
#include <vector>

#include <jelly/io/export.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/viewer/scene_adapter.hpp>

namespace jelly::viewer {

// The surfaces of every body at positions x, one OBJ object per body.
std::vector<ObjObject> surface_objects(const std::vector<BodySurface>& surfaces, const VecX& x);

// The name of frame k of an OBJ sequence: frame_0000.obj, frame_0001.obj, ... frame_12345.obj.
std::string obj_sequence_name(int frame);
// The files of DIR named as an OBJ sequence's frames (exactly as obj_sequence_name names them;
// regular files only), sorted by frame; empty when there are none or DIR is no folder.
std::vector<std::string> obj_sequence_files(const std::string& dir);

// Writes DIR/frame_0000.obj, DIR/frame_0001.obj, ... (one per recorded frame; DIR is created)
// and returns the number of files. With `replace`, the frames of an earlier sequence past this
// one's last are then removed (only files named as frames: nothing else in DIR is touched), so
// that DIR holds this sequence alone. Throws InputError for a recording without a surface or a
// folder that cannot be made.
int export_obj_sequence(const Recording& recording, const std::string& dir, bool replace = false);

// Writes the PC2 file (one sample per recorded frame, start frame 0, sample rate 1) and the
// rest surface (the surfaces at the model's rest positions, the vertex order of the cache) as
// an OBJ file of the same name with .obj, one object named after the file whose groups are the
// bodies; returns that OBJ's path.
std::string export_pc2(const Recording& recording, const std::string& pc2_path);

}  // namespace jelly::viewer
