#pragma once
// The jelly program's use of the HDF5 files of io/ (recorder, checkpoints, recording summaries),
// with their errors turned into InputErrors that name the argument.
#include <memory>
#include <string>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {
struct Checkpoint;
}

namespace jelly::cli {

// Called first in main(): the program closes its files itself, so HDF5's own clean-up at exit
// is turned off (after a failed write, a full disk, it would loop and print "infinite loop
// closing library" instead of the program's message).
void prepare_output_library();
// "<path without .h5>.xdmf": where the recorder writes the sidecar of `path`.
std::string sidecar_path_for(const std::string& path);
// An observer that records `sim` to `path` (and an XDMF sidecar); the effective scene is stored
// in the file. `overwrite`: an existing file is replaced once the new recording is complete.
// Throws InputError when the file or its sidecar cannot be created.
std::unique_ptr<Observer> make_recorder(const std::string& path, const Simulator& sim,
                                        const Scene& scene, bool overwrite);
// The last checkpoint stored in `path` (--restart), checked to belong to a run of `scene`.
std::shared_ptr<const Checkpoint> read_restart(const std::string& path, const Scene& scene);
// The simulated time a checkpoint continues from.
Real checkpoint_time(const Checkpoint& checkpoint);
// Replaces the simulator's state with the checkpoint's.
void restore_from(Simulator& sim, const Checkpoint& checkpoint, const std::string& path);
// A human-readable summary of a recording (jelly info).
std::string describe_file(const std::string& path);
// What a recording whose writing failed still holds, for the error message: "it keeps the 280
// frames written before, t = 0 .. 2.79 s" or "it cannot be read back: <why>".
std::string salvage_note(const std::string& path);

}  // namespace jelly::cli
