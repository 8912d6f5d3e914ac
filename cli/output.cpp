#include "output.hpp"

#include <exception>

#include <jelly/core/errors.hpp>

#include <jelly/io/checkpoint.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

namespace jelly::cli {

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

}  // namespace jelly::cli
