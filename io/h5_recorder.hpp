#pragma once
// An observer that records a run to an HDF5 file in the H5MD-style layout of docs/output.md
// (masses, springs, positions, velocities, observables, terrain motion, run report, a restart
// checkpoint) and writes an XDMF sidecar that ParaView opens as a time series.
#include <memory>
#include <string>

#include <jelly/solvers/simulator.hpp>

namespace jelly {

struct RecorderOptions {
  std::string scene_json;  // the whole scene as JSON text (stored as an attribute), may be empty
  std::string integrator_name;  // attribute; defaults to sim.integrator().name()
  // Frames are written in blocks of this many and the file is flushed after each block (with a
  // fresh /checkpoint): a run killed by SIGKILL leaves a file readable up to the last flush.
  int flush_every_frames = 10;
  int compression_level = 4;  // deflate (with byte shuffle) of the time series, 0 = off
  bool write_xdmf = true;     // <path without .h5>.xdmf beside the file, written at on_finish
  // Compress and write on a second thread, so that recording costs the run little wall time.
  bool background_writer = true;

  // Throws InputError for flush_every_frames < 1 or a compression level outside 0..9.
  void validate() const;
};

class H5Recorder final : public Observer {
 public:
  // Creates the file and writes the static parts (model, terrains, parameters). Throws
  // InputError if the path cannot be created (the message names the path and the reason).
  H5Recorder(const std::string& path, const Simulator& sim, RecorderOptions options = {});
  // Writes what is pending and closes the file (errors are swallowed here; on_finish reports
  // them).
  ~H5Recorder() override;
  H5Recorder(const H5Recorder&) = delete;
  H5Recorder& operator=(const H5Recorder&) = delete;

  void on_frame(const Simulator& sim) override;
  // Writes the pending frames, the run report and the integrator statistics as attributes of
  // /parameters, the final checkpoint, flushes, and writes the XDMF sidecar. May be called after
  // each of several run_until() calls. Throws std::runtime_error if a write failed.
  void on_finish(const Simulator& sim, const RunReport& report) override;

  const std::string& path() const;
  long frames() const;  // frames received so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// "<path without .h5>.xdmf".
std::string xdmf_path_for(const std::string& h5_path);

}  // namespace jelly
