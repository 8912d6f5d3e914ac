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
  std::string name;  // "<index>_<kind>"
  std::string kind;
  std::vector<Vec3> position;  // per frame
  std::map<std::string, std::string> attributes;
};

struct Recording {
  Model model;
  std::vector<Real> time;                // per frame
  std::vector<long> step;                // per frame: the simulator's total step count
  std::vector<VecX> position, velocity;  // per frame, [3N] each
  std::string scene_json;
  std::map<std::string, std::string> attributes;  // of /parameters, as text
  // /observables/<name>/value: one row per frame, 1 or 3 columns.
  std::map<std::string, Eigen::MatrixXd> observables;
  std::vector<TerrainTrack> terrains;

  int frames() const { return static_cast<int>(time.size()); }
};

// Throws InputError naming the file when it is missing, not HDF5, or not a jelly recording.
Recording read_recording(const std::string& path);
// Creator and version, particles, springs per type, frames, time range, integrator, dt, run
// status, the observables available and the file size, one item per line.
std::string describe_recording(const std::string& path);

}  // namespace jelly
