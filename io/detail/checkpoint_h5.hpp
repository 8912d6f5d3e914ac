#pragma once
// Internal: the /checkpoint group of a recording, overwritten in place at each flush.
#include <jelly/io/detail/h5.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly::h5 {

// /checkpoint attrs integrator (its name()), dt, t, total_steps, next_output, contact_count;
// datasets position [N][3], velocity [N][3] (fixed size), seed_particle [K], seed_normal [K][3],
// seed_friction [K] (resized to the current seed contacts). All in full double precision.
// After live edits of the model, the group model_values holds them: ks [M], kd [M], mass [N],
// gravity [3], pin_particle [P], pin_anchor [P][3], pin_path [P] and the attribute pin_paths
// (the paths as JSON), rewritten at each flush.
class CheckpointWriter {
 public:
  CheckpointWriter(hid_t file, int num_particles, const std::string& integrator, Real dt);
  void write(const SimulatorSnapshot& snapshot);
  // The integrator and step the last written snapshot belongs to (a live change of either, as
  // the viewer's panel makes, after the writer was made).
  void set_integrator(const std::string& integrator, Real dt);

 private:
  Handle group_, position_, velocity_, seed_particle_, seed_normal_, seed_friction_,
      integrator_state_;
  std::vector<int> particles_;
  std::vector<double> normals_, frictions_;
};

}  // namespace jelly::h5
