// solvers/: integrators by name with their options, the Simulator (step, run_until with Python
// observers, the state as NumPy views), run reports. The GIL is released while C++ steps.
#include <chrono>
#include <memory>
#include <optional>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/io/detail/run_limits.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/detail/run_fields.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/run_report.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

#include "common.hpp"
#include "fields.hpp"

namespace jelly::python {

namespace {

// An Observer subclassed in Python (on_frame, optionally on_finish). Called with the GIL
// released by run_until, so each call takes it back. The simulator is passed by pointer so that
// Python sees the simulator object it already has; the report is passed as a copy.
class PyObserver : public Observer {
 public:
  void on_frame(const Simulator& sim) override {
    py::gil_scoped_acquire gil;
    py::function f = py::get_override(static_cast<const Observer*>(this), "on_frame");
    if (!f) py::pybind11_fail("jelly.Observer.on_frame must be overridden");
    f(const_cast<Simulator*>(&sim));
  }
  void on_finish(const Simulator& sim, const RunReport& report) override {
    py::gil_scoped_acquire gil;
    py::function f = py::get_override(static_cast<const Observer*>(this), "on_finish");
    if (f) f(const_cast<Simulator*>(&sim), report);
  }
};

// run_until's `callback`: a Python callable called with the simulator at every frame.
class CallbackObserver final : public Observer {
 public:
  CallbackObserver(py::object callback, py::object simulator)
      : callback_(std::move(callback)), simulator_(std::move(simulator)) {}
  void on_frame(const Simulator& /*sim*/) override {
    py::gil_scoped_acquire gil;
    callback_(simulator_);
  }

 private:
  py::object callback_, simulator_;
};

// Lets Ctrl-C stop run_until: at its frames (every output interval; every step when it is 0),
// at most every kInterval of wall time, takes the GIL and runs Python's signal handlers; a
// KeyboardInterrupt (or any exception they raise) leaves run_until after a whole step, with the
// simulator usable. Python runs handlers in its main thread only.
class InterruptCheck final : public Observer {
 public:
  void on_frame(const Simulator& /*sim*/) override {
    const auto now = std::chrono::steady_clock::now();
    if (now < next_) return;
    next_ = now + kInterval;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }

 private:
  static constexpr std::chrono::milliseconds kInterval{20};
  std::chrono::steady_clock::time_point next_ = std::chrono::steady_clock::now() + kInterval;
};

// Removes the callback observer however run_until ends (also by a Python exception).
class ObserverGuard {
 public:
  ObserverGuard(Simulator& sim, Observer& observer) : sim_(sim), observer_(observer) {
    sim_.add_observer(observer_);
  }
  ~ObserverGuard() { sim_.remove_observer(observer_); }
  ObserverGuard(const ObserverGuard&) = delete;
  ObserverGuard& operator=(const ObserverGuard&) = delete;

 private:
  Simulator& sim_;
  Observer& observer_;
};

// A JSON object given as a dict or JSON text, parsed; InputError naming `field` otherwise.
Json json_object_of(const py::object& spec, const std::string& field) {
  const std::string text =
      py::isinstance<py::str>(spec)
          ? spec.cast<std::string>()
          : py::module_::import("json").attr("dumps")(spec).cast<std::string>();
  try {
    return Json::parse(text);
  } catch (const Json::exception&) {
    throw InputError(field, "\"" + text.substr(0, 60) + "\"", "an object as a dict or JSON text");
  }
}

py::dict statistics_dict(const Statistics& s) {
  py::dict d;
  for (const auto& [name, value] : s) d[py::str(name)] = value;
  return d;
}

py::dict report_dict(const RunReport& r) {
  py::dict d;
  d["status"] = std::string(run_status_name(r.status));
  d["t"] = r.t;
  d["steps"] = r.steps;
  d["reason"] = r.reason;
  d["wall_seconds"] = r.wall_seconds;
  d["force_evaluations"] = r.force_evaluations;
  d["notes"] = r.notes;
  d["statistics"] = statistics_dict(r.statistics);
  return d;
}

// A body given by index or by name, as its index; InputError naming `field` otherwise.
int body_index(const Simulator& sim, const py::object& body) {
  if (py::isinstance<py::str>(body)) {
    const std::string name = body.cast<std::string>();
    const Model& m = sim.model();
    for (int k = 0; k < m.num_bodies(); ++k)
      if (m.bodies[k].name == name) return k;
    throw InputError("body", "\"" + name + "\"", "the name or index of a body of the model");
  }
  return body.cast<int>();
}

SpringType spring_type_of(const py::object& type) {
  if (py::isinstance<SpringType>(type)) return type.cast<SpringType>();
  const std::string name = py::str(type).cast<std::string>();
  for (int t = 0; t < kSpringTypeCount; ++t)
    if (spring_type_name(static_cast<SpringType>(t)) == name) return static_cast<SpringType>(t);
  throw InputError("spring type", "\"" + name + "\"", "\"structural\", \"shear\" or \"bending\"");
}

// The live model's edits, the added forces and the pins driven from code.
void bind_live_model(py::class_<Simulator>& simulator) {
  simulator
      .def(
          "add_force",
          [](py::object self, const std::shared_ptr<Force>& force) {
            const ForceHandle handle = self.cast<Simulator&>().add_force(force);
            // The Python object stays alive with the simulator (its overrides live there).
            if (!py::hasattr(self, "_forces")) self.attr("_forces") = py::dict();
            self.attr("_forces")[py::int_(handle)] = py::cast(force);
            return handle;
          },
          py::arg("force"),
          "Adds a jelly.Force, evaluated at every force evaluation of every integrator until "
          "removed; returns its handle (an int) for remove_force.")
      .def(
          "remove_force",
          [](py::object self, ForceHandle handle) {
            const bool removed = self.cast<Simulator&>().remove_force(handle);
            if (removed) self.attr("_forces").attr("pop")(py::int_(handle));
            return removed;
          },
          py::arg("handle"), "Removes an added force; False when no force has this handle.")
      .def_property_readonly(
          "forces",
          [](py::object self) {
            py::list out;
            if (py::hasattr(self, "_forces"))
              for (const auto& item : self.attr("_forces").cast<py::dict>())
                out.append(item.second);
            return out;
          },
          "The added forces, in the order they act.")
      .def(
          "set_spring_coefficients",
          [](Simulator& s, const py::object& body, const py::object& type, Real ks, Real kd) {
            s.set_spring_coefficients(body_index(s, body), spring_type_of(type), {ks, kd});
          },
          py::arg("body"), py::arg("type"), py::arg("ks"), py::arg("kd"),
          "Sets ks (N/m) and kd (N s/m) of every spring of `type` (\"structural\", \"shear\", "
          "\"bending\") in `body` (index or name), for the next steps. Raises InputError naming "
          "the scene field (bodies[i].springs.<type>.ks) and changes nothing for a bad value.")
      .def(
          "set_gravity", [](Simulator& s, const Vec3& g) { s.set_gravity(g); }, py::arg("gravity"),
          "Sets gravity (m/s^2, [3]) for the next steps.")
      .def(
          "set_particle_mass",
          [](Simulator& s, const py::object& body, Real mass) {
            s.set_particle_mass(body_index(s, body), mass);
          },
          py::arg("body"), py::arg("particle_mass"),
          "Gives every particle of `body` (index or name) the mass `particle_mass` (kg, > 0).")
      .def(
          "set_integrator",
          [](Simulator& s, const std::string& name, const IntegratorOptions& options) {
            s.set_integrator(make_integrator(name, options));
          },
          py::arg("name"), py::arg("options") = IntegratorOptions{},
          "Switches to the named integrator, keeping the model, terrains, forces, pins, "
          "observers, options and state (its warm starts start afresh).")
      .def("set_dt", &Simulator::set_dt, py::arg("dt"), "Sets options.dt (s, > 0).")
      .def("set_output_interval", &Simulator::set_output_interval, py::arg("interval"),
           "Sets options.output_interval (s, >= 0; 0 = every step); the next frame is now.")
      .def("remove_terrain", &Simulator::remove_terrain, py::arg("index"),
           "Removes terrains[index].")
      .def(
          "set_pin",
          [](Simulator& s, int particle, const std::optional<Vec3>& anchor,
             const py::object& path) {
            require(particle >= 0 && particle < s.model().num_particles(), "pin particle", particle,
                    "a particle index in [0, N)");
            const Vec3 at =
                anchor ? *anchor : Vec3(s.model().rest_position.segment<3>(3 * particle));
            s.set_pin(particle, at,
                      path.is_none() ? Path() : Path::read(json_object_of(path, "path"), "path"));
          },
          py::arg("particle"), py::arg("anchor") = py::none(), py::arg("path") = py::none(),
          "Pins a particle (global index) at `anchor` (default: its rest position), moving "
          "along `path` (a scene's path object as a dict, e.g. {\"kind\": \"circle\", "
          "\"center\": [0.5, 0, 0], \"axis\": [0, 1, 0], \"period\": 2}; default fixed).")
      .def(
          "set_pin_target",
          [](Simulator& s, int particle, const Vec3& position, const Vec3& velocity) {
            s.set_pin_target(particle, position, velocity);
          },
          py::arg("particle"), py::arg("position"), py::arg("velocity") = zero_vec3_default(),
          "Drives a pinned particle from now on: at time t it is at position + velocity (t - "
          "now) (a controller's target, the mouse's drag).")
      .def("remove_pin", &Simulator::remove_pin, py::arg("particle"),
           "Frees a pinned particle; False when it was not pinned.");
}

}  // namespace

void bind_solvers(py::module_& m) {
  m.def("integrator_names", &integrator_names, "Every registered integrator's name, sorted.");
  m.def(
      "integrator_infos",
      [] {
        py::dict d;
        for (const IntegratorInfo& i : integrator_infos()) {
          d[py::str(std::string(i.name))] = std::string(i.description);
        }
        return d;
      },
      "Every registered integrator as {name: description}, sorted by name.");

  // The options classes' properties come from their field tables (fields.hpp).
  py::class_<ImplicitEulerOptions> implicit(m, "ImplicitEulerOptions",
                                            "Options of implicit_euler (docs/implicit.md).");
  implicit.def(py::init<>(), "The defaults.");
  def_fields(implicit, implicit_euler_fields());
  py::class_<ArkodeOptions> arkode(m, "ArkodeOptions",
                                   "Options of arkode_erk and arkode_dirk (docs/arkode.md).");
  arkode.def(py::init<>(), "The defaults.");
#ifdef JELLY_HAVE_ARKODE  // the table (and its linear solvers' names) is the component arkode's
  def_fields(arkode, arkode_fields());
#endif
  py::class_<ProjectiveDynamicsOptions> pd(m, "ProjectiveDynamicsOptions",
                                           "Options of projective_dynamics (docs/realtime.md).");
  pd.def(py::init<>(), "The defaults.");
  def_fields(pd, projective_dynamics_fields());
  py::class_<XpbdOptions> xpbd(m, "XpbdOptions", "Options of xpbd (docs/realtime.md).");
  xpbd.def(py::init<>(), "The defaults.");
  def_fields(xpbd, xpbd_fields());
  py::class_<VbdOptions> vbd(m, "VbdOptions", "Options of vbd (docs/realtime.md).");
  vbd.def(py::init<>(), "The defaults.");
  def_fields(vbd, vbd_fields());

  py::class_<IntegratorOptions>(
      m, "IntegratorOptions",
      "Options of the integrators that take any (scene key integrator.options).")
      .def(py::init<>(), "The defaults.")
      .def_readwrite("implicit", &IntegratorOptions::implicit, "implicit_euler's options.")
      .def_readwrite("arkode", &IntegratorOptions::arkode,
                     "arkode_erk's and arkode_dirk's options.")
      .def_readwrite("pd", &IntegratorOptions::pd, "projective_dynamics' options.")
      .def_readwrite("xpbd", &IntegratorOptions::xpbd, "xpbd's options.")
      .def_readwrite("vbd", &IntegratorOptions::vbd, "vbd's options.")
      .def(
          "validate",
          [](const IntegratorOptions& o) {
            o.implicit.validate("integrator.options.");
#ifdef JELLY_HAVE_ARKODE
            o.arkode.validate("integrator.options.");
#endif
            o.pd.validate("integrator.options.");
            o.xpbd.validate("integrator.options.");
            o.vbd.validate("integrator.options.");
          },
          "Raises InputError naming the first invalid option.");

  py::class_<Integrator>(m, "Integrator", "A time integrator (one of integrator_names()).")
      .def_property_readonly(
          "name", [](const Integrator& i) { return std::string(i.name()); }, "Its registry name.")
      .def_property_readonly("order", &Integrator::order, "Its order of accuracy.")
      .def_property_readonly("is_implicit", &Integrator::is_implicit,
                             "Whether it solves implicit equations.")
      .def_property_readonly("is_adaptive", &Integrator::is_adaptive,
                             "Whether it chooses internal steps itself.")
      .def_property_readonly("steps", &Integrator::steps, "Steps taken.")
      .def(
          "statistics", [](const Integrator& i) { return statistics_dict(i.statistics()); },
          "Its counters and timings as a dict {name: value}.")
      .def("__repr__", [](const Integrator& i) {
        return "<jelly.Integrator " + std::string(i.name()) + ": order " +
               std::to_string(i.order()) + (i.is_implicit() ? ", implicit" : ", explicit") +
               (i.is_adaptive() ? ", adaptive" : "") + ", " + std::to_string(i.steps()) + " steps>";
      });

  py::class_<DivergenceGuard> divergence(m, "DivergenceGuard",
                                         "What counts as diverged (scene key divergence).");
  divergence.def(py::init<>(), "The defaults: 500 m/s, 1e4 m, no energy cap.");
  def_fields(divergence, divergence_fields());
  divergence.def_readwrite("max_energy", &DivergenceGuard::max_energy,
                           "J; inf = not checked (not a scene key).");

  py::class_<SimulatorOptions> simulator_options(
      m, "SimulatorOptions", "Time step, output interval, threads and divergence limits.");
  def_fields(simulator_options, simulator_options_fields());
  simulator_options.def(py::init<>(), "dt 0.001 s, a frame every step.")
      .def_readwrite("divergence", &SimulatorOptions::divergence, "The DivergenceGuard.")
      .def("validate", &SimulatorOptions::validate,
           "Raises InputError naming the first invalid option.");

  py::class_<StepResult>(m, "StepResult", "The outcome of one step: ok, or a failure message.")
      .def_readonly("ok", &StepResult::ok, "False when the integrator failed (e.g. a solve).")
      .def_readonly("message", &StepResult::message, "Why it failed; empty when ok.")
      .def(
          "__bool__", [](const StepResult& r) { return r.ok; }, "Same as ok.")
      .def("__repr__", [](const StepResult& r) {
        return r.ok ? std::string("StepResult(ok=True)")
                    : "StepResult(ok=False, message='" + r.message + "')";
      });

  py::class_<RunReport>(m, "RunReport",
                        "How a run ended: status \"completed\", \"completed_with_warnings\", "
                        "\"diverged\" or \"solver_failed\" "
                        "(a diverged run returns its report, it does not raise).")
      .def_property_readonly(
          "status", [](const RunReport& r) { return std::string(run_status_name(r.status)); },
          "\"completed\", \"completed_with_warnings\", \"diverged\" or \"solver_failed\".")
      .def_property_readonly("ok", &RunReport::ok,
                             "True when completed (with or without warnings).")
      .def_readonly("t", &RunReport::t, "Simulated time reached (s).")
      .def_readonly("steps", &RunReport::steps, "Steps taken in this run.")
      .def_readonly("reason", &RunReport::reason,
                    "Why the run stopped early; empty when completed.")
      .def_readonly("wall_seconds", &RunReport::wall_seconds, "Wall time of the run (s).")
      .def_readonly("force_evaluations", &RunReport::force_evaluations,
                    "Force evaluations in this run.")
      .def_readonly("notes", &RunReport::notes,
                    "What to know that is not a warning (an added force without Jacobians "
                    "that an implicit integrator treats explicitly), each said once.")
      .def_property_readonly(
          "statistics", [](const RunReport& r) { return statistics_dict(r.statistics); },
          "The integrator's counters at the end, as a dict.")
      .def("brief", &RunReport::brief, "One line: status, time, steps, wall time (and the reason).")
      .def("as_dict", &report_dict,
           "The report as a dict (status, t, steps, reason, wall_seconds, ...).")
      .def("__repr__", [](const RunReport& r) { return "<jelly.RunReport " + r.brief() + ">"; })
      .def(py::pickle(
          [](const RunReport& r) {
            return py::make_tuple(std::string(run_status_name(r.status)), r.t, r.steps, r.reason,
                                  r.wall_seconds, r.force_evaluations, r.statistics);
          },
          [](const py::tuple& t) {
            require(t.size() == 7, "RunReport state", std::to_string(t.size()) + " items",
                    "the 7 items of a pickled RunReport");
            RunReport r;
            const std::string status = t[0].cast<std::string>();
            bool known = false;
            for (RunStatus s : {RunStatus::kCompleted, RunStatus::kCompletedWithWarnings,
                                RunStatus::kDiverged, RunStatus::kSolverFailed}) {
              if (run_status_name(s) == status) {
                r.status = s;
                known = true;
              }
            }
            require(known, "RunReport.status", status, "a run status name");
            r.t = t[1].cast<Real>();
            r.steps = t[2].cast<long>();
            r.reason = t[3].cast<std::string>();
            r.wall_seconds = t[4].cast<double>();
            r.force_evaluations = t[5].cast<long>();
            r.statistics = t[6].cast<Statistics>();
            return r;
          }));

  py::class_<Observer, PyObserver>(m, "Observer",
                                   "Subclass and override on_frame(sim) (and optionally "
                                   "on_finish(sim, report)); add with Simulator.add_observer.")
      .def(py::init<>(), "An observer; override on_frame.")
      .def("on_frame", &Observer::on_frame, py::arg("simulator"),
           "Called at the first output time and then every output interval.")
      .def("on_finish", &Observer::on_finish, py::arg("simulator"), py::arg("report"),
           "Called at the end of each run_until with its report.");

  py::class_<SimulatorSnapshot>(m, "SimulatorSnapshot",
                                "Everything the future of a run depends on besides the model, "
                                "terrains, integrator and options (bit-for-bit restarts).")
      .def_property_readonly(
          "state", [](const SimulatorSnapshot& s) { return State(s.state); }, "The state (a copy).")
      .def_readonly("total_steps", &SimulatorSnapshot::total_steps, "Steps taken so far.")
      .def_readonly("next_output", &SimulatorSnapshot::next_output, "Time of the next frame (s).")
      .def_readonly("contact_count", &SimulatorSnapshot::contact_count,
                    "Contacts of the last step.")
      .def("__repr__",
           [](const SimulatorSnapshot& s) {
             return "<jelly.SimulatorSnapshot t=" + to_text(s.state.t) + " after " +
                    std::to_string(s.total_steps) + " steps, " +
                    std::to_string(s.state.x.size() / 3) + " particles>";
           })
      .def(py::pickle(
          [](const SimulatorSnapshot& s) {
            py::list contacts;
            for (const ContactSolver::SeedContact& c : s.seed_contacts)
              contacts.append(py::make_tuple(c.particle, c.normal, c.friction));
            py::object model_values = py::none();
            if (s.model_values) {  // an edited model's values (Simulator's live edits)
              const ModelValues& values = *s.model_values;
              std::vector<std::string> paths;
              for (const Path& p : values.pins.paths) paths.push_back(p.to_json().dump());
              model_values = py::make_tuple(values.ks, values.kd, values.mass, values.gravity,
                                            values.pins.particles, values.pins.anchors,
                                            values.pins.path, paths);
            }
            return py::make_tuple(s.state.t, s.state.x, s.state.v, contacts, s.contact_count,
                                  s.total_steps, s.next_output, s.integrator_state, model_values);
          },
          [](const py::tuple& t) {
            require(t.size() == 8 || t.size() == 9, "SimulatorSnapshot state",
                    std::to_string(t.size()) + " items",
                    "the 9 items of a pickled SimulatorSnapshot");
            SimulatorSnapshot s;
            s.state.t = t[0].cast<Real>();
            s.state.x = t[1].cast<VecX>();
            s.state.v = t[2].cast<VecX>();
            for (const py::handle c : t[3].cast<py::list>()) {
              const auto item = c.cast<py::tuple>();
              s.seed_contacts.push_back(
                  {item[0].cast<int>(), item[1].cast<Vec3>(), item[2].cast<Real>()});
            }
            s.contact_count = t[4].cast<int>();
            s.total_steps = t[5].cast<long>();
            s.next_output = t[6].cast<Real>();
            s.integrator_state = t[7].cast<std::vector<Real>>();
            if (t.size() == 9 && !t[8].is_none()) {
              const auto saved = t[8].cast<py::tuple>();
              ModelValues v;
              v.ks = saved[0].cast<std::vector<Real>>();
              v.kd = saved[1].cast<std::vector<Real>>();
              v.mass = saved[2].cast<VecX>();
              v.gravity = saved[3].cast<Vec3>();
              v.pins.particles = saved[4].cast<std::vector<int>>();
              v.pins.anchors = saved[5].cast<std::vector<Vec3>>();
              v.pins.path = saved[6].cast<std::vector<int>>();
              for (const std::string& text : saved[7].cast<std::vector<std::string>>())
                v.pins.paths.push_back(Path::read(Json::parse(text), "snapshot pin path"));
              s.model_values = std::move(v);
            }
            return s;
          }));

  // dynamic_attr: the report of the last run_until is kept on the Python object (report).
  py::class_<Simulator> simulator(
      m, "Simulator", py::dynamic_attr(),
      "Steps a model among terrains with an integrator. Build it from a Scene, "
      "or from a Model, a State, an integrator name and options.");
  simulator
      .def(py::init([](const Model& model, const std::optional<State>& state,
                       const std::string& integrator, const IntegratorOptions& integrator_options,
                       const SimulatorOptions& options) {
             return Simulator(model, state ? *state : initial_state(model),
                              make_integrator(integrator, integrator_options), options);
           }),
           py::arg("model"), py::arg("state") = py::none(), py::arg("integrator") = "rk4",
           py::arg("integrator_options") = IntegratorOptions{},
           py::arg("options") = SimulatorOptions{},
           "A simulator of a model (copied) from a state (default: at rest) with the named "
           "integrator; options.threads chooses its thread count. Raises InputError for an "
           "invalid model, state or option.")
      .def(
          "add_terrain",
          [](Simulator& s, const Plane& p) { s.add_terrain(std::make_unique<Plane>(p)); },
          py::arg("terrain"), "Adds a copy of a terrain.")
      .def(
          "add_terrain",
          [](Simulator& s, const Elevator& e) { s.add_terrain(std::make_unique<Elevator>(e)); },
          py::arg("terrain"), "Adds a copy of a terrain.")
      .def(
          "add_terrain",
          [](Simulator& s, const py::object& spec) { s.add_terrain(terrain_from_spec(spec)); },
          py::arg("spec"),
          "Adds a terrain of any kind from its scene JSON (a dict or JSON text, see "
          "make_terrain).")
      .def(
          "replace_terrain",
          [](Simulator& s, int index, const Plane& p) {
            s.replace_terrain(index, std::make_unique<Plane>(p));
          },
          py::arg("index"), py::arg("terrain"),
          "Puts a copy of a terrain in place of terrains[index] (moved, reshaped or with "
          "another contact; the others keep their indices).")
      .def(
          "replace_terrain",
          [](Simulator& s, int index, const Elevator& e) {
            s.replace_terrain(index, std::make_unique<Elevator>(e));
          },
          py::arg("index"), py::arg("terrain"),
          "Puts a copy of a terrain in place of terrains[index].")
      .def(
          "replace_terrain",
          [](Simulator& s, int index, const py::object& spec) {
            s.replace_terrain(index, terrain_from_spec(spec));
          },
          py::arg("index"), py::arg("spec"),
          "Puts a terrain of any kind, from its scene JSON (a dict or JSON text), in place of "
          "terrains[index]: an obstacle moved between steps is the same spec at its new "
          "position.")
      .def("add_observer", py::overload_cast<Observer&>(&Simulator::add_observer),
           py::arg("observer"), py::keep_alive<1, 2>(),
           "Calls observer.on_frame at every output frame of run_until (and on_finish at its end).")
      .def("remove_observer", &Simulator::remove_observer, py::arg("observer"),
           "Stops calling an observer added before; False when it was not added.")
      .def(
          "step",
          [](Simulator& s, long n) {
            require(n >= 1, "n", n, "a step count >= 1");
            py::gil_scoped_release release;
            // Ctrl-C between steps, looked at most every 20 ms (Python runs its handlers in the
            // main thread only).
            auto next_check = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
            StepResult result;
            for (long k = 0; k < n; ++k) {
              result = s.step();
              if (!result.ok) break;
              if (k + 1 < n && std::chrono::steady_clock::now() >= next_check) {
                next_check = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
                py::gil_scoped_acquire gil;
                if (PyErr_CheckSignals() != 0) throw py::error_already_set();
              }
            }
            return result;
          },
          py::arg("n") = 1,
          "n steps of options.dt (default 1), each followed by contact, with the GIL released; "
          "stops at the first step the integrator fails and returns that step's StepResult (else "
          "the last one's). Does not call observers or check divergence (run_until does). "
          "Ctrl-C stops it between two steps.")
      .def(
          "reset", [](Simulator& s, const SimulatorSnapshot& snapshot) { s.restore(snapshot); },
          py::arg("snapshot"),
          "Back to a snapshot of this simulator (Simulator.snapshot()): state, contacts, clock, "
          "step count and the model's live values of then (pins and their targets, spring "
          "coefficients, masses, gravity), bit for bit. Added forces, terrains and the integrator "
          "stay as they are. The arrays of sim.state keep their memory (views stay valid).")
      .def(
          "reset", [](Simulator& s, const State& state) { s.set_state(state); }, py::arg("state"),
          "Back to a state (positions, velocities, t): as set_state, the active contacts are "
          "forgotten and the output clock restarts; the model's live values stay as they are.")
      .def(
          "run_until",
          [](py::object self, Real t_end, py::object callback) {
            Simulator& sim = self.cast<Simulator&>();
            std::optional<CallbackObserver> observer;
            std::optional<ObserverGuard> guard;
            if (!callback.is_none()) {
              observer.emplace(callback, self);
              guard.emplace(sim, *observer);
            }
            check_run_until(sim, t_end);  // jelly run's limits: steps, rounding
            InterruptCheck interrupt;
            ObserverGuard interrupt_guard(sim, interrupt);
            RunReport report;
            {
              py::gil_scoped_release release;
              report = sim.run_until(t_end);
            }
            self.attr("_last_report") = report;
            return report;
          },
          py::arg("t_end"), py::arg("callback") = py::none(),
          "Steps until t_end, calling observers (and callback(sim), if given) at every output "
          "frame, and returns a RunReport; stops early on divergence or solver failure, which "
          "the report's status says (no exception). The GIL is released while stepping and "
          "taken back for each Python call. Raises InputError for a run jelly run refuses "
          "(more than 10^9 steps, a time at which dt is lost to rounding). Ctrl-C "
          "(KeyboardInterrupt) stops it at the next frame; the simulator stays usable.")
      .def_property_readonly(
          "report",
          [](py::object self) -> py::object {
            return py::getattr(self, "_last_report", py::none());
          },
          "The RunReport of the last run_until (None before the first): status, t, steps, "
          "as_dict(), the integrator's statistics.")
      .def_property_readonly(
          "model", [](const Simulator& s) -> const Model& { return s.model(); },
          py::return_value_policy::reference_internal, "The model (read-only views).")
      .def_property(
          "state", [](Simulator& s) -> State& { return s.mutable_state(); },
          [](Simulator& s, const State& state) { s.set_state(state); },
          py::return_value_policy::reference_internal,
          "The current State; its x and v are (N, 3) views of the simulator's memory, and "
          "assigning state.x / state.v copies into it in place (kept contacts and clock). "
          "Assigning a whole State is a restart (set_state).")
      .def(
          "set_state", [](Simulator& s, const State& state) { s.set_state(state); },
          py::arg("state"),
          "Replaces the state (a restart): forgets the active contacts, restarts the output clock.")
      .def("set_anchors", &Simulator::set_anchors, py::arg("anchors"),
           "Springs pulling particles to points (a list of AnchorSpring), part of the forces of "
           "every step until replaced ([] removes them); implicit integrators take them into "
           "their solve. Raises InputError for an invalid anchor. Not part of snapshots.")
      .def_property_readonly("anchors", &Simulator::anchors, "The anchors in force (copies).")
      .def(
          "snapshot",
          [](const Simulator& s, bool model) {
            SimulatorSnapshot snapshot = s.snapshot();
            // The model as built: its values too, so that a reset after live edits puts them
            // back.
            if (model && !snapshot.model_values) {
              const Model& built = s.model();
              snapshot.model_values = ModelValues{built.springs.ks, built.springs.kd, built.mass,
                                                  built.gravity, built.pins};
            }
            return snapshot;
          },
          py::arg("model") = true,
          "A SimulatorSnapshot to restore later (bit for bit): the state, contacts, clock and "
          "the model's live values (pins and their targets, coefficients, masses, gravity), "
          "which reset/restore put back. model=False leaves the values out unless the model "
          "was edited (as the C++ Simulator::snapshot), for restoring the state into a "
          "simulator of another model.")
      .def("restore", &Simulator::restore, py::arg("snapshot"),
           "Continues from a snapshot of a simulator with the same model, terrains, integrator "
           "and options.")
      .def_property_readonly(
          "integrator", [](Simulator& s) -> Integrator& { return s.integrator(); },
          py::return_value_policy::reference_internal, "The Integrator (name, statistics()).")
      .def_property_readonly(
          "options", [](const Simulator& s) { return SimulatorOptions(s.options()); },
          "The SimulatorOptions (a copy: writing to it changes nothing; options.threads is "
          "set_threads).")
      .def("set_threads", &Simulator::set_threads, py::arg("threads"),
           "Sets options.threads: threads for the force loop, the solves and the contact, 0 = "
           "all cores (the same results bit for bit). Raises InputError for a negative count.")
      .def_property_readonly(
          "terrains",
          [](py::object self) {
            py::list out;
            for (const auto& t : self.cast<const Simulator&>().terrains()) {
              out.append(py::cast(t.get(), py::return_value_policy::reference_internal, self));
            }
            return out;
          },
          "The terrains (views; alive with the simulator).")
      .def_property_readonly(
          "t", [](const Simulator& s) { return s.state().t; }, "The current time (s).")
      .def_property_readonly("total_steps", &Simulator::total_steps, "Steps taken since creation.")
      .def_property_readonly("force_evaluations", &Simulator::force_evaluations,
                             "Force evaluations since creation.")
      .def_property_readonly(
          "contact_count", [](const Simulator& s) { return s.contacts().contact_count(); },
          "Particles in contact with terrains after the last step.")
      .def(
          "set_body_contact",
          [](Simulator& s, const py::object& spec) {
            const Json j = json_object_of(spec, "body_contact");
            JsonFields f(j, "body_contact");
            s.set_body_contact(BodyContactParams::read(f));
          },
          py::arg("spec"),
          "Contact between bodies and within one (a scene's \"body_contact\" object as a dict "
          "or JSON text: enabled, self_contact, restitution, friction, static_friction, "
          "resting_speed, iterations; missing keys keep their defaults). Raises InputError "
          "naming the field.")
      .def_property_readonly(
          "body_contact",
          [](const Simulator& s) {
            return py::module_::import("json").attr("loads")(
                s.body_contact().params().to_json().dump());
          },
          "The body contact parameters in force, as a dict (a scene's \"body_contact\").")
      .def_property_readonly(
          "body_contact_pairs",
          [](const Simulator& s) {
            const auto& pairs = s.body_contact().pairs();
            Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor> out(pairs.size(), 2);
            for (std::size_t k = 0; k < pairs.size(); ++k) {
              out(k, 0) = pairs[k].first;
              out(k, 1) = pairs[k].second;
            }
            return out;
          },
          "The particle pairs (i < j, global indices) of different bodies (or, with "
          "self_contact, of one body) in contact after the last step, int32 [P, 2] (a copy).")
      .def(
          "kinetic_energy", [](const Simulator& s) { return kinetic_energy(s.model(), s.state()); },
          "Kinetic energy of the current state (J).")
      .def(
          "elastic_energy", [](const Simulator& s) { return elastic_energy(s.model(), s.state()); },
          "Elastic energy of the current state (J).")
      .def(
          "gravitational_energy",
          [](const Simulator& s) { return gravitational_energy(s.model(), s.state()); },
          "Gravitational energy of the current state (J).")
      .def(
          "total_energy", [](const Simulator& s) { return total_energy(s.model(), s.state()); },
          "Kinetic + elastic + gravitational energy of the current state (J).")
      .def(
          "center_of_mass", [](const Simulator& s) { return center_of_mass(s.model(), s.state()); },
          "Centre of mass of the current state (m), [3].")
      .def(
          "linear_momentum",
          [](const Simulator& s) { return linear_momentum(s.model(), s.state()); },
          "Linear momentum of the current state (kg m/s), [3].")
      .def(
          "angular_momentum",
          [](const Simulator& s) { return angular_momentum(s.model(), s.state()); },
          "Angular momentum about the origin (kg m^2/s), [3].")
      .def("__repr__", [](const Simulator& s) {
        return "<jelly.Simulator " + std::string(s.integrator().name()) + ", dt " +
               to_text(s.options().dt) + ", t=" + to_text(s.state().t) + ", " +
               std::to_string(s.model().num_particles()) + " particles, " +
               std::to_string(s.terrains().size()) + " terrains, " +
               std::to_string(s.total_steps()) + " steps>";
      });
  bind_live_model(simulator);
}

}  // namespace jelly::python
