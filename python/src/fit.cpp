// fit/: spring and damper coefficients fitted to a recording (docs/fitting.md), with the options
// and report of `jelly fit`.
#include <jelly/fit/detail/recording_trajectory.hpp>
#include <jelly/fit/spring_fit.hpp>
#include <jelly/io/recording.hpp>

#include "common.hpp"

namespace jelly::python {

namespace {

std::string free_names(const std::vector<FitParameter>& free) {
  std::string out;
  for (const FitParameter& p : free) out += (out.empty() ? "" : ",") + p.name();
  return out;
}

}  // namespace

void bind_fit(py::module_& m) {
  py::class_<FitOptions>(m, "FitOptions", "Options of fit_recording (those of jelly fit and more).")
      .def(py::init<>(), "The defaults: free 'ks,kd', window 0.1 s, 50 iterations.")
      .def_property(
          "free", [](const FitOptions& o) { return free_names(o.free); },
          [](FitOptions& o, const std::string& list) { o.free = parse_free_parameters(list); },
          "The free coefficients, comma-separated: 'ks,kd', 'ks.structural,ks.shear,kd', ...")
      .def_property(
          "gradients",
          [](const FitOptions& o) { return std::string(fit_gradients_name(o.gradients)); },
          [](FitOptions& o, const std::string& name) {
            o.gradients = fit_gradients_from_name(name, "gradients");
          },
          "'auto' (the adjoint of implicit_euler when it supports the recording, else numeric), "
          "'adjoint' or 'numeric' (docs/fitting.md).")
      .def_readwrite("initial", &FitOptions::initial,
                     "Starting values by parameter name ({'ks': 1400}); others start at the "
                     "recording's own coefficients.")
      .def_readwrite("window", &FitOptions::window,
                     "Multiple-shooting window (s); 0 = whole recording.")
      .def_readwrite("max_iterations", &FitOptions::max_iterations,
                     "Levenberg-Marquardt iterations.")
      .def_readwrite("function_tolerance", &FitOptions::function_tolerance,
                     "Ceres' function tolerance.")
      .def_readwrite("gradient_tolerance", &FitOptions::gradient_tolerance,
                     "Ceres' gradient tolerance.")
      .def_readwrite("parameter_tolerance", &FitOptions::parameter_tolerance,
                     "Ceres' parameter tolerance.")
      .def_readwrite("fit_restart_velocities", &FitOptions::fit_restart_velocities,
                     "Make each window's initial velocity unknowns too.")
      .def_readwrite("relative_step", &FitOptions::relative_step,
                     "Step of the central differences on log k.")
      .def_readwrite("num_threads", &FitOptions::num_threads, "Threads for Ceres' residual blocks.")
      .def_readwrite("compute_covariance", &FitOptions::compute_covariance,
                     "Compute standard deviations (costs more than the fit).")
      .def_readwrite("progress_to_stdout", &FitOptions::progress_to_stdout,
                     "Ceres' progress lines.")
      .def("validate", &FitOptions::validate, "Raises InputError naming the first invalid option.");

  py::class_<FittedParameter>(m, "FittedParameter", "One fitted coefficient.")
      .def_readonly("name", &FittedParameter::name, "'ks', 'kd.shear', ...")
      .def_readonly("initial", &FittedParameter::initial, "Start value.")
      .def_readonly("value", &FittedParameter::value, "Estimate.")
      .def_readonly("stddev", &FittedParameter::stddev,
                    "Standard deviation accounting for the restart states' noise (NaN if unknown).")
      .def_readonly("stddev_independent", &FittedParameter::stddev_independent,
                    "The textbook s^2 (J^T J)^-1 standard deviation.")
      .def("__repr__", [](const FittedParameter& p) {
        return "<jelly.FittedParameter " + p.name + " = " + to_text(p.value) + " +- " +
               to_text(p.stddev) + ">";
      });

  py::class_<FitResult>(m, "FitResult",
                        "The outcome of fit_recording; report() prints as jelly fit.")
      .def_readonly("parameters", &FitResult::parameters,
                    "The FittedParameters, in the order of free.")
      .def_readonly("initial_cost", &FitResult::initial_cost, "1/2 sum r^2 at the start (m^2).")
      .def_readonly("final_cost", &FitResult::final_cost, "1/2 sum r^2 at the end (m^2).")
      .def_readonly("iterations", &FitResult::iterations, "Iterations.")
      .def_readonly("converged", &FitResult::converged, "Ceres terminated with CONVERGENCE.")
      .def_readonly("termination", &FitResult::termination, "Ceres' message.")
      .def_readonly("brief_report", &FitResult::brief_report, "Ceres' BriefReport().")
      .def_readonly("covariance_ok", &FitResult::covariance_ok,
                    "Whether the covariance was computed.")
      .def_readonly("covariance_message", &FitResult::covariance_message, "Why not, when not.")
      .def_readonly("residual_rms", &FitResult::residual_rms, "sqrt(2 final_cost / residuals) (m).")
      .def_readonly("windows", &FitResult::windows, "Shooting windows.")
      .def_readonly("residuals", &FitResult::residuals, "Residuals.")
      .def_readonly("replays", &FitResult::replays, "Window replays.")
      .def_readonly("gradient_path", &FitResult::gradient_path, "'adjoint' or 'numeric'.")
      .def_readonly("gradient_reason", &FitResult::gradient_reason,
                    "Why the numeric path was taken (empty on the adjoint path).")
      .def_readonly("adjoint_passes", &FitResult::adjoint_passes,
                    "Window replays differentiated by the adjoint.")
      .def_readonly("adjoint_integrator", &FitResult::adjoint_integrator,
                    "The integrator whose adjoint gave the gradients (the recording's; empty on "
                    "the numeric path).")
      .def_readonly("wall_seconds", &FitResult::wall_seconds, "Wall time of the whole call (s).")
      .def_readonly("covariance_seconds", &FitResult::covariance_seconds,
                    "Of which the covariance (s).")
      .def(
          "at", [](const FitResult& r, const std::string& name) { return r.at(name); },
          py::arg("name"),
          "The estimate named 'ks', 'kd.shear', ...; raises InputError for a name not fitted.")
      .def(
          "values",
          [](const FitResult& r) {
            py::dict d;
            for (const FittedParameter& p : r.parameters) d[py::str(p.name)] = p.value;
            return d;
          },
          "The estimates as {name: value}.")
      .def("report", &FitResult::report,
           "The report jelly fit prints: estimates +- sd, costs, iterations.")
      .def("__str__", &FitResult::report, "The report.")
      .def("__repr__", [](const FitResult& r) {
        return "<jelly.FitResult " + std::to_string(r.parameters.size()) + " parameters, " +
               std::to_string(r.iterations) + " iterations, " +
               (r.converged ? "converged" : "not converged") + ">";
      });

  m.def(
      "parse_free_parameters",
      [](const std::string& list) {
        std::vector<std::string> names;
        for (const FitParameter& p : parse_free_parameters(list)) names.push_back(p.name());
        return names;
      },
      py::arg("list"),
      "The names of a free-parameter list ('ks,kd'); raises InputError (field 'free') for an "
      "unknown name, a duplicate or an overlap.");

  m.def(
      "_fit_recording",
      [](const PyRecording& r, const FitOptions& options) {
        py::gil_scoped_release release;
        return fit_recording(trajectory_from_recording(r.recording), options);
      },
      py::arg("recording"), py::arg("options"),
      "Fits the recording's coefficients (jelly.fit_recording is the documented entry).");
  m.def(
      "_fitted_scene",
      [](const PyRecording& r, const FitResult& result) {
        return fitted_scene(r.recording, result);
      },
      py::arg("recording"), py::arg("result"),
      "The recording's scene with the fitted coefficients (jelly.fitted_scene wraps it).");
}

}  // namespace jelly::python
