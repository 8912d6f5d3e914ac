#pragma once
// A restart point of a run, stored in a recording's /checkpoint group: everything a simulator
// with the same model, terrains, integrator and options needs to continue bit for bit.
#include <string>
#include <vector>

#include <jelly/solvers/simulator.hpp>

namespace jelly {

struct Checkpoint {
  State state;
  long total_steps = 0;
  Real next_output = 0;  // time of the next observer frame
  std::vector<ContactSolver::SeedContact> seed_contacts;
  int contact_count = 0;
  std::vector<Real> integrator_state;  // empty in files written before it was stored
  std::string integrator;              // of the run that wrote it
  Real dt = 0;                         // of the run that wrote it

  SimulatorSnapshot snapshot() const;
};

// The checkpoint a recording holds (written at its last flush or at the end of its run). Throws
// InputError for a missing or invalid file, or one without a checkpoint, naming it.
Checkpoint read_checkpoint(const std::string& path);

// Continues `sim` from the checkpoint. Throws InputError when the particle count, integrator or
// time step differ from the run that wrote it (the continuation could not be the same run); use
// sim.restore(cp.snapshot()) to continue with other settings on purpose.
void restore(Simulator& sim, const Checkpoint& cp);

}  // namespace jelly
