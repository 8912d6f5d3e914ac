#include "output.hpp"

#include <exception>

#include <jelly/core/errors.hpp>

// The HDF5 modules live on their own branch (io-h5); the merged tree has them.
#if __has_include(<jelly/io/h5_recorder.hpp>) && __has_include(<jelly/io/checkpoint.hpp>) && \
    __has_include(<jelly/io/recording.hpp>)
#define JELLY_CLI_HAS_HDF5 1
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#else
#define JELLY_CLI_HAS_HDF5 0
#endif

namespace jelly::cli {

namespace {
[[maybe_unused]] InputError unavailable(const std::string& what) {
  return InputError(what +
                    " is not available in this build (jelly was built without its HDF5 "
                    "module, io/h5_recorder.hpp)");
}
}  // namespace

bool hdf5_output_available() { return JELLY_CLI_HAS_HDF5 != 0; }

#if JELLY_CLI_HAS_HDF5

std::unique_ptr<Observer> make_recorder(const std::string& path, const Simulator& sim,
                                        const Scene& scene) {
  RecorderOptions options;
  options.scene_json = scene_to_json(scene);
  options.integrator_name = scene.integrator.name;
  try {
    return std::make_unique<H5Recorder>(path, sim, options);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("-o " + path + ": cannot create the file: " + e.what());
  }
}

void restore_from_file(Simulator& sim, const std::string& path) {
  const auto checkpoint = [&] {
    try {
      return read_checkpoint(path);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError("--restart " + path + ": " + e.what());
    }
  }();
  restore(sim, checkpoint);
}

std::string describe_file(const std::string& path) {
  try {
    return describe_recording(path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": " + e.what());
  }
}

#else

std::unique_ptr<Observer> make_recorder(const std::string& path, const Simulator& /*sim*/,
                                        const Scene& /*scene*/) {
  throw unavailable("-o " + path + ": HDF5 output");
}

void restore_from_file(Simulator& /*sim*/, const std::string& path) {
  throw unavailable("--restart " + path + ": reading checkpoints");
}

std::string describe_file(const std::string& path) {
  throw unavailable("info " + path + ": reading HDF5 files");
}

#endif

}  // namespace jelly::cli
