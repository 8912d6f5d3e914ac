#pragma once
// A restart point of a run, stored in a recording's /checkpoint group: everything a simulator
// with the same model, terrains, integrator and options needs to continue bit for bit.
#include <optional>
#include <string>
#include <vector>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

// What a simulator needs to continue a run bit for bit: its state, counters, carried contacts,
// integrator state and the model's edited values.
struct Checkpoint {
  State state;                                // time, positions, velocities
  long total_steps = 0;                       // steps taken since the run began
  Real next_output = 0;                       // time of the next observer frame
  std::vector<CarriedContact> seed_contacts;  // contacts the seed rules carry into the next step
  int contact_count = 0;                      // contacts resolved so far
  std::vector<Real> integrator_state;         // empty in files written before it was stored
  std::string integrator;                     // of the run that wrote it
  Real dt = 0;                                // of the run that wrote it
  Real output_interval = 0;                   // of the run that wrote it
  std::string scene_json;  // the scene of the run that wrote it (empty when none was stored)
  // The model's values after live edits of the run that wrote it (none without edits).
  std::optional<ModelValues> model_values;

  SimulatorSnapshot snapshot() const;  // the simulator's snapshot to restore
};

// The checkpoint a recording holds (written at its last flush or at the end of its run). Throws
// InputError for a missing or invalid file, or one without a checkpoint, naming it.
Checkpoint read_checkpoint(const std::string& path);

// Continues `sim` from the checkpoint. Throws InputError when the particle count, integrator or
// time step differ from the run that wrote it (the continuation could not be the same run), or
// when its times are not those of a run (t, or the next output time, far from where the run
// was); use sim.restore(cp.snapshot()) to continue with other settings on purpose.
void restore(Simulator& sim, const Checkpoint& cp);

// Throws InputError naming the first JSON path (e.g. "springs.structural.ks") at which `scene`
// differs from the scene the checkpoint's run was recorded with, or when that scene is missing
// or unreadable: a restart continues the same run. duration, output_interval, divergence and
// description may differ. `source` names the file in messages.
void check_same_scene(const Checkpoint& cp, const Scene& scene, const std::string& source);

}  // namespace jelly
