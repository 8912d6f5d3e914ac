#include "output.hpp"

#include <exception>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>

namespace jelly::cli {

void prepare_output_library() { disable_hdf5_exit_cleanup(); }

std::string sidecar_path_for(const std::string& path) { return xdmf_path_for(path); }

std::unique_ptr<Observer> make_recorder(const std::string& path, const Simulator& sim,
                                        const Scene& scene, bool overwrite) {
  RecorderOptions options;
  options.scene_json = scene_to_json(scene);
  options.integrator_name = scene.integrator.name;
  options.overwrite = overwrite;
  try {
    return std::make_unique<H5Recorder>(path, sim, options);
  } catch (const InputError& e) {
    throw InputError("-o " + path + ": " + e.what());
  } catch (const std::exception& e) {
    throw InputError("-o " + path + ": cannot create the file: " + e.what());
  }
}

std::shared_ptr<const Checkpoint> read_restart(const std::string& path, const Scene& scene) {
  auto checkpoint = std::make_shared<Checkpoint>([&] {
    try {
      return read_checkpoint(path);
    } catch (const InputError& e) {
      throw InputError("--restart " + path + ": " + e.what());
    } catch (const std::exception& e) {
      throw InputError("--restart " + path + ": " + e.what());
    }
  }());
  check_same_scene(*checkpoint, scene, path);
  return checkpoint;
}

Real checkpoint_time(const Checkpoint& checkpoint) { return checkpoint.state.t; }

void restore_from(Simulator& sim, const Checkpoint& checkpoint, const std::string& path) {
  try {
    restore(sim, checkpoint);
  } catch (const InputError& e) {
    throw InputError("--restart " + path + ": " + e.what());
  }
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

std::string salvage_note(const std::string& path) {
  try {
    const std::string text = describe_recording(path);
    const std::string key = "frames:        ";
    const std::size_t at = text.find(key);
    if (at == std::string::npos) return "it holds no frames";
    const std::size_t end = text.find('\n', at);
    // "280, t = 0 .. 2.79 s" -> "it keeps the 280 frames written before, t = 0 .. 2.79 s".
    const std::string frames = text.substr(at + key.size(), end - at - key.size());
    const std::size_t comma = frames.find(',');
    return "it keeps the " + frames.substr(0, comma) + " frames written before" +
           (comma == std::string::npos ? "" : frames.substr(comma));
  } catch (const std::exception& e) {
    return std::string("it cannot be read back: ") + e.what();
  }
}

}  // namespace jelly::cli
