#pragma once
// A recording read back from an HDF5 file written by H5Recorder, and the summary `jelly info`
// prints about one.
#include <map>
#include <string>
#include <vector>

#include <jelly/core/model.hpp>

namespace jelly {

// A terrain's recorded motion: /terrain/<name>/position and the group's attributes.
struct TerrainTrack {
  std::string name;                               // "<index>_<kind>"
  std::string kind;                               // the terrain kind
  std::vector<Vec3> position;                     // per frame
  std::map<std::string, std::string> attributes;  // the group's attributes, as text
};

// A recording read back (read_recording): the model, the frames' times, positions and velocities,
// observables and terrain tracks.
struct Recording {
  Model model;                                    // the model the run simulated
  std::vector<Real> time;                         // per frame
  std::vector<long> step;                         // per frame: the simulator's total step count
  std::vector<VecX> position;                     // per frame, [3N] each (m)
  std::vector<VecX> velocity;                     // per frame, [3N] each (m/s)
  std::string scene_json;                         // the scene of the run, JSON text (may be empty)
  std::map<std::string, std::string> attributes;  // of /parameters, as text
  // /observables/<name>/value: one row per frame, 1 or 3 columns.
  std::map<std::string, Eigen::MatrixXd> observables;
  std::vector<TerrainTrack> terrains;  // each terrain's recorded motion

  // The number of frames.
  int frames() const { return static_cast<int>(time.size()); }
};

// The exact times of recorded frames. A recorded time is a sum of steps (2.9999999999997806);
// one within dt / 1000 of a multiple k x output_interval is that product (3), else one within
// dt / 1000 of a multiple of dt is that product; any other (adaptive steps) stays as recorded.
// dt <= 0: as recorded.
std::vector<Real> exact_frame_times(const std::vector<Real>& time, Real dt, Real output_interval);
// Of a recording, with its /parameters dt and output_interval (as recorded when it has none).
std::vector<Real> exact_frame_times(const Recording& recording);

// Throws InputError naming the file when it is missing, not HDF5, or not a jelly recording.
Recording read_recording(const std::string& path);
// Creator and version, particles, springs per type, frames, time range, integrator, dt, run
// status, the observables available and the file size, one item per line.
std::string describe_recording(const std::string& path);

}  // namespace jelly
