// geometry/: the body kinds a scene can name (jelly.body_kinds()) and the seed cube built in code
// (CubeSpec, build_cube). Scenes describe bodies of every kind in their "bodies" list.
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/cube.hpp>

#include "common.hpp"

namespace jelly::python {

void bind_geometry(py::module_& m) {
  m.def(
      "body_kinds",
      [] {
        py::dict d;
        for (const BodyKindInfo& k : body_kinds()) {
          d[py::str(std::string(k.name))] = std::string(k.description);
        }
        return d;
      },
      "Every body kind a scene's \"bodies\" can name, as {name: description with its keys}, "
      "sorted by name.");
  m.def("cube_particle_count", &cube_particle_count, py::arg("n"),
        "Particles of an n x n x n cube: n^3.");
  m.def("cube_spring_count", &cube_spring_count, py::arg("n"),
        "Springs of an n x n x n cube (12,876 for n = 10).");

  py::class_<CubeSpec>(m, "CubeSpec",
                       "The seed's jelly cube: an n x n x n lattice with structural, shear and "
                       "bending springs. Defaults are the seed's (n 10, edge 4 m, ks 1400, kd 50).")
      .def(py::init<>(), "The seed cube.")
      .def_readwrite("n", &CubeSpec::n, "Particles per edge, >= 2.")
      .def_readwrite("edge_length", &CubeSpec::edge_length, "Edge length (m), > 0.")
      .def_readwrite("origin", &CubeSpec::origin, "Position of particle (0, 0, 0) (m).")
      .def_readwrite("particle_mass", &CubeSpec::particle_mass, "Mass of each particle (kg).")
      .def_readwrite("gravity", &CubeSpec::gravity, "Gravity (m/s^2).")
      .def(
          "springs",
          [](CubeSpec& c, const py::object& type) -> SpringCoefficients& {
            return c.springs[static_cast<int>(spring_type_from(type))];
          },
          py::arg("type"), py::return_value_policy::reference_internal,
          "The coefficients of one spring type (a SpringType or its name), modifiable in place.")
      .def(
          "set_springs",
          [](CubeSpec& c, const py::object& type, Real ks, Real kd) {
            c.springs[static_cast<int>(spring_type_from(type))] = {ks, kd};
          },
          py::arg("type"), py::arg("ks"), py::arg("kd"),
          "Sets ks (N/m) and kd (N s/m) of one spring type (a SpringType or its name).")
      .def("validate", &CubeSpec::validate, "Raises InputError naming the first invalid field.");

  m.def("build_cube", &build_cube, py::arg("spec"),
        "The cube model of a CubeSpec: particle (i, j, k) has index (i*n + j)*n + k.");
  m.def("cube_index", &cube_index, py::arg("n"), py::arg("i"), py::arg("j"), py::arg("k"),
        "Index of lattice particle (i, j, k) of an n x n x n cube: (i*n + j)*n + k.");
}

}  // namespace jelly::python
