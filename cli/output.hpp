#pragma once
// The jelly program's use of the HDF5 files of io/ (recorder, checkpoints, recording summaries),
// with their errors turned into InputErrors that name the argument.
#include <memory>
#include <string>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly::cli {

// An observer that records `sim` to `path` (and an XDMF sidecar); the effective scene is stored
// in the file. Throws InputError when the file cannot be created.
std::unique_ptr<Observer> make_recorder(const std::string& path, const Simulator& sim,
                                        const Scene& scene);
// Replaces the simulator's state with the last checkpoint stored in `path` (--restart).
void restore_from_file(Simulator& sim, const std::string& path);
// A human-readable summary of a recording (jelly info).
std::string describe_file(const std::string& path);

}  // namespace jelly::cli
