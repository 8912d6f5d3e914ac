// io/: scenes (JSON in, JSON out, validated by the C++ parser), simulators made from scenes,
// the HDF5 recorder, recordings read back as NumPy arrays, checkpoints and restarts.
#include <atomic>
#include <chrono>
#include <future>

#include <jelly/core/detail/json.hpp>
#include <jelly/io/checkpoint.hpp>
#include <jelly/io/detail/rollout.hpp>
#include <jelly/io/detail/run_limits.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>

#include "common.hpp"

namespace jelly::python {

namespace {

// H5Recorder with an explicit close(): the file must be closed before h5py or read_recording
// can open it in the same process, and Python does not promise when an object is destroyed.
class PyH5Recorder final : public Observer {
 public:
  PyH5Recorder(const std::string& path, const Simulator& sim, RecorderOptions options)
      : path_(path), impl_(std::make_unique<H5Recorder>(path, sim, std::move(options))) {}
  void on_frame(const Simulator& sim) override { open().on_frame(sim); }
  void on_finish(const Simulator& sim, const RunReport& report) override {
    open().on_finish(sim, report);
  }
  void check_simulator(const Simulator& sim) const override {
    if (!impl_) {
      throw InputError("the recorder of '" + path_ +
                       "' is closed: make a new H5Recorder to record another run");
    }
    impl_->check_simulator(sim);
  }
  // Leaves every simulator it was added to, then closes the file.
  void close() {
    leave_simulators();
    if (impl_) frames_ = impl_->frames();
    impl_.reset();
  }
  bool closed() const { return impl_ == nullptr; }
  const std::string& path() const { return path_; }
  long frames() const { return impl_ ? impl_->frames() : frames_; }

 private:
  H5Recorder& open() {
    if (!impl_) {
      throw InputError("the recorder of '" + path_ +
                       "' is closed: remove it from the simulator (remove_observer) first");
    }
    return *impl_;
  }
  std::string path_;
  std::unique_ptr<H5Recorder> impl_;
  long frames_ = 0;  // at close()
};

py::array stack_frames(const std::vector<VecX>& frames, int n) {
  py::array_t<Real> out(
      {static_cast<py::ssize_t>(frames.size()), static_cast<py::ssize_t>(n), py::ssize_t{3}});
  Real* p = out.mutable_data();
  for (const VecX& f : frames) p = std::copy(f.data(), f.data() + f.size(), p);
  return out;
}

// A rollout's [runs][frames][particles][3] vector as a NumPy array over its memory, owned by the
// Python Rollout object `owner` (writeable: the arrays are the caller's data).
py::array rollout_array(const std::vector<Real>& values, const RolloutResult& r, py::handle owner) {
  const auto s = static_cast<py::ssize_t>(sizeof(Real));
  const py::ssize_t runs = r.runs, frames = r.frames, n = r.particles;
  return py::array(py::dtype::of<Real>(), {runs, frames, n, py::ssize_t{3}},
                   {frames * n * 3 * s, n * 3 * s, 3 * s, s}, values.data(), owner);
}

py::dict rollout_run_dict(const RolloutRun& run) {
  py::dict d;
  d["status"] = run.status;
  d["reason"] = run.reason;
  d["t"] = run.t;
  d["steps"] = run.steps;
  d["frames"] = run.frames;
  d["wall_seconds"] = run.wall_seconds;
  return d;
}

// Rollout's pickled state: the sizes, the arrays (copies) and the runs as tuples.
py::tuple rollout_state(const RolloutResult& r) {
  py::list runs;
  for (const RolloutRun& run : r.run)
    runs.append(
        py::make_tuple(run.status, run.reason, run.t, run.steps, run.frames, run.wall_seconds));
  return py::make_tuple(
      r.runs, r.frames, r.particles,
      py::bytes(reinterpret_cast<const char*>(r.positions.data()),
                r.positions.size() * sizeof(Real)),
      py::bytes(reinterpret_cast<const char*>(r.velocities.data()),
                r.velocities.size() * sizeof(Real)),
      py::bytes(reinterpret_cast<const char*>(r.times.data()), r.times.size() * sizeof(Real)), runs,
      r.wall_seconds, r.threads);
}

std::vector<Real> reals_of(const py::bytes& b) {
  const std::string text = b;
  std::vector<Real> out(text.size() / sizeof(Real));
  std::copy(text.data(), text.data() + out.size() * sizeof(Real),
            reinterpret_cast<char*>(out.data()));
  return out;
}

RolloutResult rollout_from_state(const py::tuple& t) {
  require(t.size() == 9, "Rollout state", std::to_string(t.size()) + " items",
          "the 9 items of a pickled Rollout");
  RolloutResult r;
  r.runs = t[0].cast<long>();
  r.frames = t[1].cast<long>();
  r.particles = t[2].cast<long>();
  r.positions = reals_of(t[3]);
  r.velocities = reals_of(t[4]);
  r.times = reals_of(t[5]);
  for (const py::handle item : t[6].cast<py::list>()) {
    const auto run = item.cast<py::tuple>();
    r.run.push_back({run[0].cast<std::string>(), run[1].cast<std::string>(), run[2].cast<Real>(),
                     run[3].cast<long>(), run[4].cast<long>(), run[5].cast<double>()});
  }
  r.wall_seconds = t[7].cast<double>();
  r.threads = t[8].cast<int>();
  const auto values = static_cast<std::size_t>(r.runs * r.frames * r.particles * 3);
  require(r.positions.size() == values && (r.velocities.empty() || r.velocities.size() == values) &&
              r.times.size() == static_cast<std::size_t>(r.runs * r.frames) &&
              r.run.size() == static_cast<std::size_t>(r.runs),
          "Rollout state", "arrays of other sizes", "the sizes of a pickled Rollout");
  return r;
}

void bind_rollout(py::module_& m) {
  py::class_<RolloutResult>(
      m, "Rollout",
      "The result of jelly.rollout: positions (and velocities) of every run at every frame as "
      "NumPy arrays over its own memory, the frame times, and how each run ended.")
      .def_property_readonly(
          "positions",
          [](py::object self) {
            const auto& r = self.cast<const RolloutResult&>();
            return rollout_array(r.positions, r, self);
          },
          "Positions (m), float64 [runs, frames, particles, 3] (a view of the result's memory, "
          "no copy); NaN after a run's last frame.")
      .def_property_readonly(
          "velocities",
          [](py::object self) -> py::object {
            const auto& r = self.cast<const RolloutResult&>();
            if (r.velocities.empty()) return py::none();
            return rollout_array(r.velocities, r, self);
          },
          "Velocities (m/s) in the layout of positions, or None unless rollout(velocities=True).")
      .def_property_readonly(
          "times",
          [](py::object self) {
            const auto& r = self.cast<const RolloutResult&>();
            const auto s = static_cast<py::ssize_t>(sizeof(Real));
            return py::array(py::dtype::of<Real>(), {py::ssize_t(r.runs), py::ssize_t(r.frames)},
                             {py::ssize_t(r.frames) * s, s}, r.times.data(), self);
          },
          "Time of each frame (s), [runs, frames]; NaN after a run's last frame.")
      .def_property_readonly(
          "status",
          [](const RolloutResult& r) {
            std::vector<std::string> out;
            for (const RolloutRun& run : r.run) out.push_back(run.status);
            return out;
          },
          "Each run's status: \"completed\", \"completed_with_warnings\", \"diverged\", "
          "\"solver_failed\", \"failed\" (it raised; the reason is the message) or "
          "\"stopped\".")
      .def_property_readonly(
          "reasons",
          [](const RolloutResult& r) {
            std::vector<std::string> out;
            for (const RolloutRun& run : r.run) out.push_back(run.reason);
            return out;
          },
          "Why each run stopped early (or its warnings); \"\" for a completed run.")
      .def_property_readonly(
          "ok",
          [](const RolloutResult& r) {
            py::array_t<bool> out(static_cast<py::ssize_t>(r.runs));
            for (long k = 0; k < r.runs; ++k) out.mutable_at(k) = r.run[k].ok();
            return out;
          },
          "Whether each run reached the duration, bool [runs].")
      .def_property_readonly(
          "frames",
          [](const RolloutResult& r) {
            py::array_t<long> out(static_cast<py::ssize_t>(r.runs));
            for (long k = 0; k < r.runs; ++k) out.mutable_at(k) = r.run[k].frames;
            return out;
          },
          "Frames each run kept, int [runs] (the arrays have max(frames) frames).")
      .def_property_readonly(
          "steps",
          [](const RolloutResult& r) {
            py::array_t<long> out(static_cast<py::ssize_t>(r.runs));
            for (long k = 0; k < r.runs; ++k) out.mutable_at(k) = r.run[k].steps;
            return out;
          },
          "Steps each run took, int [runs].")
      .def_property_readonly(
          "runs",
          [](const RolloutResult& r) {
            py::list out;
            for (const RolloutRun& run : r.run) out.append(rollout_run_dict(run));
            return out;
          },
          "Each run as a dict: status, reason, t, steps, frames, wall_seconds.")
      .def_readonly("wall_seconds", &RolloutResult::wall_seconds,
                    "Wall time of the whole rollout (s).")
      .def_readonly("threads", &RolloutResult::threads, "Runs that went at once.")
      .def(
          "__len__", [](const RolloutResult& r) { return r.runs; }, "The number of runs.")
      .def(py::pickle([](const RolloutResult& r) { return rollout_state(r); },
                      [](const py::tuple& t) { return rollout_from_state(t); }))
      .def("__repr__", [](const RolloutResult& r) {
        long ok = 0;
        for (const RolloutRun& run : r.run) ok += run.ok() ? 1 : 0;
        return "<jelly.Rollout " + std::to_string(r.runs) + " runs (" + std::to_string(ok) +
               " ok), " + std::to_string(r.frames) + " frames of " + std::to_string(r.particles) +
               " particles" + (r.velocities.empty() ? "" : ", with velocities") + ">";
      });

  m.def(
      "_rollout",
      [](const std::string& scene_json, const std::vector<std::vector<std::string>>& overrides,
         const std::string& source, const std::string& base_directory, Real duration, Real every,
         bool velocities, int threads) {
        std::atomic<bool> stop{false};
        RolloutOptions options;
        options.duration = duration;
        options.every = every;
        options.velocities = velocities;
        options.threads = threads;
        options.stop = &stop;
        bool interrupted = false;
        RolloutResult result;
        {
          py::gil_scoped_release release;
          // The runs on their own threads; this one looks at Python's signals every 20 ms (a
          // Ctrl-C stops every run at its next frame; only the main thread sees signals).
          auto runs = std::async(std::launch::async, [&] {
            return rollout(scene_json, overrides, options, source, base_directory);
          });
          while (runs.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready) {
            if (interrupted) continue;
            py::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() != 0) {  // the exception stays set until we raise it
              interrupted = true;
              stop = true;
            }
          }
          result = runs.get();  // rethrows an InputError of the rollout
        }
        if (interrupted) throw py::error_already_set();
        return result;
      },
      py::arg("scene_json"), py::arg("overrides_per_run"), py::arg("source"),
      py::arg("base_directory"), py::arg("duration"), py::arg("every"), py::arg("velocities"),
      py::arg("threads"),
      "The C++ jelly::rollout (jelly.rollout wraps it): runs on a pool of threads without the "
      "GIL; Ctrl-C stops the runs at their next frame and raises KeyboardInterrupt.");
}

}  // namespace

void bind_io(py::module_& m) {
  bind_rollout(m);
  py::class_<Scene>(m, "_Scene",
                    "The C++ scene (jelly.Scene wraps it: attribute access by JSON path).")
      .def(py::init([](const std::string& json_text, const std::vector<std::string>& overrides,
                       const std::string& source, const std::string& base_directory) {
             return parse_scene(json_text, overrides, source, base_directory);
           }),
           py::arg("json_text"), py::arg("overrides") = std::vector<std::string>{},
           py::arg("source") = "scene", py::arg("base_directory") = "",
           "Parses and validates scene JSON (after applying overrides); raises InputError naming "
           "the JSON path of the first invalid field. Files the scene names (a body's mesh) are "
           "relative to base_directory (\"\" = the current directory).")
      .def(
          "_assign",
          [](Scene& s, const std::string& json_text, const std::string& source,
             const std::string& base_directory) {
            s = parse_scene(json_text, {}, source, base_directory);
          },
          py::arg("json_text"), py::arg("source") = "scene", py::arg("base_directory") = "",
          "Replaces this scene by the parsed JSON text; unchanged when it is invalid.")
      .def(
          "to_json", [](const Scene& s) { return scene_to_json(s); },
          "The scene as pretty-printed JSON with every field written out.")
      .def("validate", &Scene::validate, "Raises InputError naming the first invalid field.");

  m.def(
      "_load_scene",
      [](const std::string& path, const std::vector<std::string>& overrides) {
        return load_scene(path, overrides);
      },
      py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
      "The C++ load_scene (jelly.load_scene wraps it in a jelly.Scene).");
  m.def(
      "apply_override",
      [](const std::string& json_text, const std::string& assignment) {
        return apply_override(json_text, assignment);
      },
      py::arg("json_text"), py::arg("assignment"),
      "Applies one 'path=value' assignment (jelly run --set) to scene JSON text and returns the "
      "new text (not validated).");
  m.def(
      "scene_to_json", [](const Scene& s) { return scene_to_json(s); }, py::arg("scene"),
      "The scene as pretty-printed JSON with every field written out.");

  m.def("make_model", &make_model, py::arg("scene"),
        "The scene's model: its bodies (every kind of body_kinds()) with their pins and "
        "external forces, and gravity; jelly.Simulator(model, ...) runs it without the scene's "
        "terrains.");

  auto simulator = py::reinterpret_borrow<py::class_<Simulator>>(m.attr("Simulator"));
  simulator.def(py::init([](const Scene& scene) { return make_simulator(scene); }),
                py::arg("scene"),
                "The scene's bodies at rest (with their pins and forces) among its terrains, with "
                "its integrator and options "
                "(as jelly run makes it). Run it with sim.run_until(scene.duration).");

  py::class_<RecorderOptions>(m, "RecorderOptions", "Options of H5Recorder (docs/output.md).")
      .def(py::init<>(), "The defaults.")
      .def_readwrite("scene_json", &RecorderOptions::scene_json, "The scene stored in the file.")
      .def_readwrite("integrator_name", &RecorderOptions::integrator_name,
                     "Attribute; default: the simulator's.")
      .def_readwrite(
          "flush_every_frames", &RecorderOptions::flush_every_frames,
          "Frames per block at most (fewer when a block would exceed 8 MiB of particle data); the "
          "file is flushed after each block.")
      .def_readwrite("compression_level", &RecorderOptions::compression_level,
                     "Deflate 0..9, 0 = off.")
      .def_readwrite("write_xdmf", &RecorderOptions::write_xdmf,
                     "Write the .xdmf sidecar at each run's end.")
      .def_readwrite("background_writer", &RecorderOptions::background_writer,
                     "Compress and write on a second thread.")
      .def_readwrite("overwrite", &RecorderOptions::overwrite,
                     "Replace an existing file (written aside, moved on at the first on_finish); "
                     "False: an existing file is an InputError.");

  py::class_<PyH5Recorder, Observer>(m, "H5Recorder",
                                     "An observer recording a run to HDF5 (+ XDMF sidecar). Add it "
                                     "with sim.add_observer(recorder); close() (or a with block) "
                                     "before reading the file in the same process.")
      .def(py::init([](const std::string& path, const py::object& sim_object, const Scene* scene,
                       std::optional<RecorderOptions> options) {
             SimulatorLock lock(sim_object);
             const Simulator& sim = sim_object.cast<const Simulator&>();
             RecorderOptions o = options ? *options : RecorderOptions{};
             if (scene != nullptr) {  // as `jelly run -o` records a scene
               o.scene_json = scene_to_json(*scene);
               o.integrator_name = scene->integrator.name;
             }
             return std::make_unique<PyH5Recorder>(path, sim, std::move(o));
           }),
           py::arg("path"), py::arg("simulator"), py::arg("scene") = nullptr,
           py::arg("options") = py::none(),
           "Creates the file and writes the static parts of the simulator. With a scene, the "
           "scene's JSON and integrator name are stored as jelly run stores them. Raises "
           "InputError when the file cannot be created. It records only that simulator's "
           "model: add_observer raises InputError for another.")
      .def("close", &PyH5Recorder::close,
           "Removes the recorder from every simulator it was added to, writes what is pending "
           "and closes the file.")
      .def_property_readonly("closed", &PyH5Recorder::closed, "Whether close() was called.")
      .def_property_readonly("path", &PyH5Recorder::path, "The file's path.")
      .def_property_readonly("frames", &PyH5Recorder::frames, "Frames received so far.")
      .def(
          "__enter__", [](py::object self) { return self; }, "Returns the recorder.")
      .def(
          "__exit__", [](PyH5Recorder& r, py::args) { r.close(); },
          "Closes the recorder (which removes it from its simulators).")
      .def("__repr__", [](const PyH5Recorder& r) {
        return "<jelly.H5Recorder '" + r.path() + "', " + std::to_string(r.frames()) + " frames" +
               (r.closed() ? ", closed>" : ">");
      });

  py::class_<PyRecording>(m, "Recording",
                          "A recording read back from HDF5: arrays of time, positions, "
                          "velocities and observables.")
      .def_property_readonly(
          "model", [](const PyRecording& r) -> const Model& { return r.recording.model; },
          py::return_value_policy::reference_internal, "Masses, springs and gravity.")
      .def_property_readonly(
          "time", [](const PyRecording& r) { return py::array(py::cast(r.recording.time)); },
          "Time of each frame (s), [T].")
      .def_property_readonly(
          "step", [](const PyRecording& r) { return py::array(py::cast(r.recording.step)); },
          "The simulator's total step count at each frame, [T].")
      .def_property_readonly(
          "position",
          [](PyRecording& r) {
            if (!r.position)
              r.position = stack_frames(r.recording.position, r.recording.model.num_particles());
            return r.position;
          },
          "Positions (m), [T, N, 3] (built once).")
      .def_property_readonly(
          "velocity",
          [](PyRecording& r) {
            if (!r.velocity)
              r.velocity = stack_frames(r.recording.velocity, r.recording.model.num_particles());
            return r.velocity;
          },
          "Velocities (m/s), [T, N, 3] (built once).")
      .def_property_readonly(
          "observables",
          [](const PyRecording& r) {
            py::dict d;
            for (const auto& [name, value] : r.recording.observables) {
              if (value.cols() == 1) {
                d[py::str(name)] = Eigen::VectorXd(value.col(0));
              } else {
                d[py::str(name)] = value;
              }
            }
            return d;
          },
          "{name: array [T] or [T, 3]}: kinetic_energy, elastic_energy, gravitational_energy, "
          "total_energy, center_of_mass, linear_momentum, angular_momentum.")
      .def_property_readonly(
          "terrains",
          [](const PyRecording& r) {
            py::list out;
            for (const TerrainTrack& t : r.recording.terrains) {
              py::dict d;
              d["name"] = t.name;
              d["kind"] = t.kind;
              Eigen::Matrix<Real, Eigen::Dynamic, 3, Eigen::RowMajor> p(t.position.size(), 3);
              for (std::size_t k = 0; k < t.position.size(); ++k)
                p.row(k) = t.position[k].transpose();
              d["position"] = p;
              d["attributes"] = t.attributes;
              out.append(d);
            }
            return out;
          },
          "The terrains' recorded motion: [{name, kind, position [T, 3], attributes}].")
      .def_property_readonly(
          "scene_json", [](const PyRecording& r) { return r.recording.scene_json; },
          "The scene the run was made from (JSON text; empty if none was stored).")
      .def_property_readonly(
          "attributes", [](const PyRecording& r) { return r.recording.attributes; },
          "The attributes of /parameters, as text (run_status, dt, integrator, ...).")
      .def_property_readonly(
          "frames", [](const PyRecording& r) { return r.recording.frames(); },
          "Number of frames T.")
      .def_property_readonly(
          "path", [](const PyRecording& r) { return r.path; },
          "The absolute path of the file it was read from.")
      .def(py::pickle([](const PyRecording& r) { return py::make_tuple(r.path); },
                      [](const py::tuple& t) {
                        PyRecording r;
                        r.path = t[0].cast<std::string>();
                        r.recording = read_recording(r.path);
                        return r;
                      }))
      .def("__repr__", [](const PyRecording& r) {
        return "<jelly.Recording " + std::to_string(r.recording.frames()) + " frames of " +
               std::to_string(r.recording.model.num_particles()) + " particles>";
      });

  m.def(
      "read_recording",
      [](const std::string& path) {
        PyRecording r;
        r.path = py::module_::import("os").attr("path").attr("abspath")(path).cast<std::string>();
        {
          py::gil_scoped_release release;
          r.recording = read_recording(path);
        }
        return r;
      },
      py::arg("path"),
      "Reads a recording written by H5Recorder or jelly run -o. Raises InputError naming the "
      "file when it is missing, not HDF5 or not a jelly recording.");
  m.def("describe_recording", &describe_recording, py::arg("path"),
        "What a recording holds, one item per line (as jelly info prints it).");
  m.def(
      "write_xdmf_for_recording",
      [](const std::string& path) { return write_xdmf_for_recording(path); }, py::arg("path"),
      "Writes the XDMF sidecar of an existing recording (e.g. of a killed run) and returns its "
      "path.");

  py::class_<Checkpoint>(m, "Checkpoint", "A restart point stored in a recording's /checkpoint.")
      .def_property_readonly(
          "state", [](const Checkpoint& c) { return State(c.state); }, "The state (a copy).")
      .def_readonly("total_steps", &Checkpoint::total_steps, "Steps taken by then.")
      .def_readonly("next_output", &Checkpoint::next_output, "Time of the next frame (s).")
      .def_readonly("integrator", &Checkpoint::integrator,
                    "The integrator of the run that wrote it.")
      .def_readonly("dt", &Checkpoint::dt, "The time step of the run that wrote it (s).")
      .def_readonly("output_interval", &Checkpoint::output_interval,
                    "The output interval of the run that wrote it (s).")
      .def_readonly("scene_json", &Checkpoint::scene_json,
                    "The scene of the run that wrote it (empty when none was stored).")
      .def("snapshot", &Checkpoint::snapshot, "As a SimulatorSnapshot (Simulator.restore).")
      .def("__repr__", [](const Checkpoint& c) {
        return "<jelly.Checkpoint t=" + to_text(c.state.t) + " after " +
               std::to_string(c.total_steps) + " steps, " + c.integrator + ", dt " + to_text(c.dt) +
               ">";
      });
  m.def(
      "_check_run_limits",
      [](const Scene& scene, const std::string& output) {
        RunLimits limits;
        if (!output.empty()) limits.disk_bytes = free_disk_bytes(output);
        check_run_limits(scene, 0, limits, output);
      },
      py::arg("scene"), py::arg("output") = "",
      "The limits jelly run checks before a run of the scene (steps, frames, memory, the "
      "recording's size at `output`); raises InputError naming the field.");
  m.def("read_checkpoint", &read_checkpoint, py::arg("path"),
        "The checkpoint a recording holds. Raises InputError for a missing or invalid file.");
  m.def(
      "check_same_scene",
      [](const Checkpoint& cp, const Scene& scene, const std::string& source) {
        check_same_scene(cp, scene, source);
      },
      py::arg("checkpoint"), py::arg("scene"), py::arg("source") = "checkpoint",
      "Raises InputError naming the first JSON path at which the scene differs from the one the "
      "checkpoint's run was recorded with (duration, output_interval, divergence and "
      "description may differ): a restart continues the same run.");
  m.def("restore", &restore, py::arg("simulator"), py::arg("checkpoint"),
        "Continues a simulator from a checkpoint, bit for bit; raises InputError when its "
        "particle count, integrator or time step differ from the run that wrote it.");
}

}  // namespace jelly::python
