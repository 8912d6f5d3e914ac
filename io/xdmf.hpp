#pragma once
// The XDMF sidecar of a recording, for ParaView: <path without .h5>.xdmf beside the .h5.
//
// Every ParaView XDMF reader opens it (Xdmf3ReaderS, the default, Xdmf3ReaderT and the older
// "XDMF Reader"), from any working directory. The Xdmf3 readers of VTK read no HyperSlab or
// Function DataItem (vtkXdmf3DataSet asks such an array for its number type before reading it,
// gets "None" and drops it), and the XDMF Reader reports an error for any Geometry whose first
// DataItem has no text of its own, so every DataItem of the sidecar names one whole HDF5
// dataset. What the recording does not hold in that form is written into it, under /xdmf: one
// HDF5 virtual dataset per frame viewing that frame of /particles/<body>/position/value and of
// /particles/<body>/surface/position/value (no copy), the derived arrays (speed per particle and
// per surface vertex, strain per spring) and the terrain meshes. Each body is a block of its
// particles and springs, followed by a block of its render surface when it has one; then come
// the terrains.
// docs/output.md describes the sidecar and the /xdmf group.
#include <string>

namespace jelly {

struct XdmfOptions {
  // Strain of every spring at every frame (|xa - xb| / rest length - 1) as a cell array: float32
  // [T][M], the largest part of /xdmf.
  bool strain = true;
  int compression_level = 1;  // deflate (with byte shuffle) of the derived arrays, 0 = off

  // Throws InputError for a compression level outside 0..9.
  void validate() const;
};

// Writes the sidecar of the recording at h5_path and what it needs under /xdmf in the recording
// (opened for writing). Called again after more frames were recorded (or on a file whose run
// was killed), it adds what the new frames need and rewrites the sidecar. Returns the sidecar's
// path. Throws InputError for a missing or invalid file or options.
std::string write_xdmf_for_recording(const std::string& h5_path, const XdmfOptions& options = {});

// Where write_paraview_state puts the state of the recording at h5_path: <path without .h5>
// .paraview.py beside it.
std::string paraview_state_path_for(const std::string& h5_path);
// Writes a ParaView Python state beside the recording whose sidecar was written (File > Load
// State, `paraview --state=FILE`, or pvpython FILE): it opens the sidecar with ParaView's default
// reader, colours by speed over the range of every frame (/xdmf attribute speed_range) and points
// the camera at the bodies' bounding box over the whole run (/xdmf attribute bounds). The file is
// data: jelly writes it and never runs it. Returns its path. Throws InputError when the
// recording has no sidecar data (/xdmf) yet.
std::string write_paraview_state(const std::string& h5_path);

}  // namespace jelly
