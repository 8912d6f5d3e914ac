#include <jelly/core/components.hpp>

// The io component (HDF5, JSON): scene files, the recorder, recordings, checkpoints, exports.
namespace jelly {

void register_io_component() {
  register_component({"io",
                      "scene files (JSON), HDF5 recorder and recordings, checkpoints, "
                      "XDMF, exports, rollouts (HDF5)"});
}

}  // namespace jelly
