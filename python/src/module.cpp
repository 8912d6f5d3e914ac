// The Python module jelly._jelly (re-exported by the package `jelly`): the C++ library's
// modules bound one file each, in layer order.
#include <jelly/version.hpp>

#include "common.hpp"

PYBIND11_MODULE(_jelly, m) {
  namespace py = pybind11;
  m.doc() = "jelly: a mass-spring soft-body solver (C++17), bound with pybind11.";
  // Bad user input: the C++ message names the field (a scene's JSON path), the value and what
  // is allowed.
  auto input_error = py::register_exception<jelly::InputError>(m, "InputError", PyExc_ValueError);
  input_error.attr("__module__") = "jelly";
  input_error.attr("__doc__") =
      "Bad user input (a scene, an option, an argument, a file): the message names the field "
      "(a scene's JSON path), the value and what is allowed. A ValueError.";
  m.attr("__version__") = JELLY_VERSION_STRING;
  jelly::python::bind_core(m);
  jelly::python::bind_geometry(m);
  jelly::python::bind_terrain(m);
  jelly::python::bind_solvers(m);
  jelly::python::bind_io(m);
#ifdef JELLY_HAVE_FIT
  jelly::python::bind_fit(m);
#endif
  jelly::python::bind_adjoint(m);
  jelly::python::bind_dlpack(m);
  jelly::python::serialise_simulator(m);
}
