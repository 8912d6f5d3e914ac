#pragma once
// The XDMF sidecar of a recording: a temporal collection of one uniform grid per frame, whose
// topology (a polyline per spring), geometry and attributes point into the HDF5 file, so that
// ParaView's "XDMF Reader" shows the jelly and its springs as a time series. (The "Xdmf3 Reader"
// variants of ParaView 5.11 load no points from HyperSlab geometry; docs/output.md.)
#include <string>
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

struct XdmfLayout {
  std::string h5_file;  // as referenced from the .xdmf: usually the file name alone (beside it)
  int num_particles = 0;
  int num_springs = 0;
  std::vector<Real> times;  // one per recorded frame
};

std::string xdmf_text(const XdmfLayout& layout);
// Throws InputError naming the path if it cannot be written.
void write_xdmf(const std::string& xdmf_path, const XdmfLayout& layout);
// Writes <h5 path without .h5>.xdmf for an existing recording (e.g. one whose run was killed
// before it could write its own). Throws InputError for a missing or invalid file.
void write_xdmf_for_recording(const std::string& h5_path);

}  // namespace jelly
