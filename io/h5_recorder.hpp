#pragma once
// An observer that records a run to an HDF5 file in the H5MD-style layout of docs/output.md
// (masses, springs, positions, velocities, observables, terrain motion, run report, a restart
// checkpoint) and writes an XDMF sidecar that ParaView opens as a time series.
#include <memory>
#include <string>

#include <jelly/solvers/simulator.hpp>

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
namespace jelly {

// What the XDMF sidecar of a recording shows.
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

namespace jelly {

// How an H5Recorder writes: compression, blocks of frames, sidecar, overwriting.
struct RecorderOptions {
  std::string scene_json;  // the whole scene as JSON text (stored as an attribute), may be empty
  std::string integrator_name;  // attribute; defaults to sim.integrator().name()
  // Frames are written in blocks of at most this many (fewer when they would exceed 8 MiB of
  // particle data: docs/output.md) and the file is flushed after each block (with a fresh
  // /checkpoint): a run killed by SIGKILL leaves a file readable up to the last flush.
  int flush_every_frames = 10;
  int compression_level = 4;  // deflate (with byte shuffle) of the time series, 0 = off
  bool write_xdmf = true;     // <path without .h5>.xdmf beside the file, written at on_finish
  XdmfOptions xdmf;           // what the sidecar shows (io/h5_recorder.hpp)
  // Compress and write on a second thread, so that recording costs the run little wall time.
  bool background_writer = true;
  // A recorder never destroys a file it did not create unless told to. false: an existing file at
  // the path (or at its sidecar's path) is an InputError. true: the recording is written beside
  // it under a temporary name ("<path>.partial-<pid>") and replaces it only when the first
  // on_finish() has written it completely; a run that throws or is killed before that leaves the
  // old file untouched (and, when killed, the partial file).
  bool overwrite = false;

  // Throws InputError for flush_every_frames < 1 or a compression level outside 0..9.
  void validate() const;
};

// An observer that records a run into an HDF5 file (H5MD layout, docs/output.md) with its XDMF
// sidecar and a checkpoint that restarts it.
class H5Recorder final : public Observer {
 public:
  // Creates the file and writes the static parts (model, terrains, parameters). Throws
  // InputError if the path cannot be created (the message names the path and the reason), if it
  // or its sidecar exists without options.overwrite, if the sidecar could not be written (found
  // now, not after the run), or if the path is its own sidecar's (a name ending in .xdmf).
  H5Recorder(const std::string& path, const Simulator& sim, RecorderOptions options = {});
  // Writes what is pending and closes the file (errors are swallowed here; on_finish reports
  // them).
  ~H5Recorder() override;
  H5Recorder(const H5Recorder&) = delete;
  H5Recorder& operator=(const H5Recorder&) = delete;

  // Records the frame (positions, velocities, observables, terrain positions).
  void on_frame(const Simulator& sim) override;
  // Writes the pending frames, the run report and the integrator statistics as attributes of
  // /parameters, the final checkpoint, flushes, and writes the XDMF sidecar (under a temporary
  // name, then renamed); with options.overwrite the first call then moves the recording onto
  // its path. May be called after each of several run_until() calls. Throws std::runtime_error
  // if a write failed.
  void on_finish(const Simulator& sim, const RunReport& report) override;
  // Throws InputError naming both particle counts and bodies when `sim` is not the simulator
  // this recorder was made for (another model: other particles, springs or bodies) or has fewer
  // terrains than it had then.
  void check_simulator(const Simulator& sim) const override;

  // The scene the run goes on with after a live change (the viewer's panel: integrator, dt,
  // coefficients, gravity, contact), stored as /parameters scene_json and integrator at the next
  // on_finish(), so that a restart continues the run as it went on. (on_finish() always stores
  // the checkpoint's integrator and dt as they are then.)
  void set_scene(const std::string& scene_json, const std::string& integrator_name);

  const std::string& path() const;  // the file it writes
  long frames() const;              // frames received so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// "<path without .h5>.xdmf".
std::string xdmf_path_for(const std::string& h5_path);

// For programs, first thing in main(): turns off HDF5's own clean-up at exit. A program that
// closes its recorders and readers itself (their destructors do) loses nothing; after a failed
// write (a full disk) that clean-up would otherwise loop over the file it cannot flush and print
// "HDF5: infinite loop closing library" after the program's own message.
void disable_hdf5_exit_cleanup();

}  // namespace jelly
