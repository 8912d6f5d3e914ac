#pragma once
// The seam between the jelly program and the HDF5 output of io/ (recorder, checkpoints,
// recording summaries). A build without io/h5_recorder.hpp still runs scenes; asking it for a
// file is an InputError "... not available in this build".
#include <memory>
#include <string>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly::cli {

// Whether this build can write HDF5 files (-o), read them (info) and restart from them.
bool hdf5_output_available();
// An observer that records `sim` to `path` (and an XDMF sidecar); the effective scene is stored
// in the file. Throws InputError when the file cannot be created.
std::unique_ptr<Observer> make_recorder(const std::string& path, const Simulator& sim,
                                        const Scene& scene);
// Replaces the simulator's state with the last checkpoint stored in `path` (--restart).
void restore_from_file(Simulator& sim, const std::string& path);
// A human-readable summary of a recording (jelly info).
std::string describe_file(const std::string& path);

}  // namespace jelly::cli
