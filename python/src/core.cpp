// core/: the model (masses, springs as NumPy arrays), the state, the cube builder, energies and
// momenta.
#include <jelly/core/anchor_springs.hpp>
#include <jelly/core/cube.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>

#include "common.hpp"

namespace jelly::python {

namespace {

SpringType spring_type_from(const py::object& type) {
  if (py::isinstance<py::str>(type)) {
    const std::string name = type.cast<std::string>();
    for (int t = 0; t < kSpringTypeCount; ++t) {
      if (spring_type_name(static_cast<SpringType>(t)) == name) return static_cast<SpringType>(t);
    }
    throw InputError("spring type", "\"" + name + "\"", "\"structural\", \"shear\" or \"bending\"");
  }
  return type.cast<SpringType>();
}

}  // namespace

void bind_core(py::module_& m) {
  py::enum_<SpringType>(m, "SpringType", "The three spring types of the seed cube.")
      .value("structural", SpringType::kStructural)
      .value("shear", SpringType::kShear)
      .value("bending", SpringType::kBending);
  m.def(
      "spring_type_names",
      [] {
        std::vector<std::string> names;
        for (int t = 0; t < kSpringTypeCount; ++t) {
          names.emplace_back(spring_type_name(static_cast<SpringType>(t)));
        }
        return names;
      },
      "The spring type names, by type index: ['structural', 'shear', 'bending'].");

  py::class_<SpringCoefficients>(m, "SpringCoefficients",
                                 "Stiffness ks (N/m) and damping kd (N s/m) of one spring type.")
      .def(py::init([](Real ks, Real kd) {
             return SpringCoefficients{ks, kd};
           }),
           py::arg("ks") = 1400, py::arg("kd") = 50, "Coefficients ks (N/m) and kd (N s/m).")
      .def_readwrite("ks", &SpringCoefficients::ks, "Stiffness (N/m).")
      .def_readwrite("kd", &SpringCoefficients::kd, "Damping (N s/m).")
      .def("__repr__", [](const SpringCoefficients& c) {
        return "SpringCoefficients(ks=" + to_text(c.ks) + ", kd=" + to_text(c.kd) + ")";
      });

  py::class_<Springs>(m, "Springs",
                      "Springs stored once each as parallel arrays (read-only NumPy views of the "
                      "C++ memory; other coefficients: a scene with them, or build_cube).")
      .def_property_readonly(
          "a",
          [](py::object self) {
            const Springs& s = self.cast<const Springs&>();
            return view(s.a.data(), s.size(), self);
          },
          "First particle index of each spring, int32 [M].")
      .def_property_readonly(
          "b",
          [](py::object self) {
            const Springs& s = self.cast<const Springs&>();
            return view(s.b.data(), s.size(), self);
          },
          "Second particle index of each spring, int32 [M].")
      .def_property_readonly(
          "rest_length",
          [](py::object self) {
            const Springs& s = self.cast<const Springs&>();
            return view(s.rest_length.data(), s.size(), self);
          },
          "Rest length of each spring (m), float64 [M].")
      .def_property_readonly(
          "ks",
          [](py::object self) {
            const Springs& s = self.cast<const Springs&>();
            return view(s.ks.data(), s.size(), self);
          },
          "Stiffness of each spring (N/m), float64 [M].")
      .def_property_readonly(
          "kd",
          [](py::object self) {
            const Springs& s = self.cast<const Springs&>();
            return view(s.kd.data(), s.size(), self);
          },
          "Damping of each spring (N s/m), float64 [M].")
      .def_property_readonly(
          "type",
          [](py::object self) {
            const Springs& s = self.cast<const Springs&>();
            static_assert(sizeof(SpringType) == sizeof(std::uint8_t));
            return view(reinterpret_cast<const std::uint8_t*>(s.type.data()), s.size(), self);
          },
          "Type of each spring (0 structural, 1 shear, 2 bending), uint8 [M].")
      .def("__len__", &Springs::size, "The number of springs.")
      .def(
          "count",
          [](const Springs& s, const py::object& type) { return s.count(spring_type_from(type)); },
          py::arg("type"), "The number of springs of a type (a SpringType or its name).");

  py::class_<Model>(m, "Model",
                    "The mass-spring model: particle masses, springs and gravity. Arrays are "
                    "read-only NumPy views of the C++ memory.")
      .def_property_readonly(
          "mass",
          [](py::object self) {
            const Model& md = self.cast<const Model&>();
            return view(md.mass.data(), md.mass.size(), self);
          },
          "Particle masses (kg), float64 [N].")
      .def_property_readonly(
          "rest_position",
          [](py::object self) { return view_n3(self.cast<const Model&>().rest_position, self); },
          "The positions the rest lengths were measured in (m), float64 [N, 3].")
      .def_property_readonly(
          "springs", [](const Model& md) -> const Springs& { return md.springs; },
          py::return_value_policy::reference_internal, "The springs (Springs).")
      .def_property_readonly(
          "gravity", [](const Model& md) { return Vec3(md.gravity); },
          "Gravity (m/s^2), a copy [3].")
      .def_property_readonly("num_particles", &Model::num_particles, "The number of particles N.")
      .def_property_readonly(
          "num_springs", [](const Model& md) { return md.springs.size(); },
          "The number of springs M.")
      .def("validate", &Model::validate,
           "Raises InputError when a mass, index, rest length or coefficient is out of range.")
      .def("__repr__", [](const Model& md) {
        return "<jelly.Model with " + std::to_string(md.num_particles()) + " particles and " +
               std::to_string(md.springs.size()) + " springs>";
      });

  py::class_<State>(m, "State",
                    "Time, positions and velocities. x and v read as (N, 3) NumPy views of the C++ "
                    "memory (no copy, read-only); assigning to them copies into that memory.")
      .def(py::init([](const DoubleArray& x, const DoubleArray& v, Real t) {
             State s;
             s.t = t;
             s.x = flat_n3(x, "state.x");
             s.v = flat_n3(v, "state.v");
             require(s.v.size() == s.x.size(), "state.v.size", s.v.size(), "the size of state.x");
             return s;
           }),
           py::arg("x"), py::arg("v"), py::arg("t") = 0.0,
           "A state from positions and velocities, each of shape (N, 3) or (3N,), copied.")
      .def_readwrite("t", &State::t, "Time (s).")
      .def_property(
          "x", [](py::object self) { return view_n3(self.cast<State&>().x, self); },
          [](State& s, const DoubleArray& x) { assign_n3(s.x, x, "state.x"); },
          "Positions (m): reading gives a read-only (N, 3) view of the C++ memory; assigning an "
          "(N, 3) or (3N,) array copies it in.")
      .def_property(
          "v", [](py::object self) { return view_n3(self.cast<State&>().v, self); },
          [](State& s, const DoubleArray& v) { assign_n3(s.v, v, "state.v"); },
          "Velocities (m/s): reading gives a read-only (N, 3) view of the C++ memory; assigning "
          "an (N, 3) or (3N,) array copies it in.")
      .def_property_readonly(
          "num_particles", [](const State& s) { return s.x.size() / 3; },
          "The number of particles N.")
      .def(
          "copy", [](const State& s) { return State(s); }, "An independent copy of the state.")
      .def("__repr__", [](const State& s) {
        return "<jelly.State t=" + to_text(s.t) + " with " + std::to_string(s.x.size() / 3) +
               " particles>";
      });

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
  m.def("rest_state", &rest_state, py::arg("model"),
        "The model at rest in its construction pose, at t = 0.");
  m.def("cube_index", &cube_index, py::arg("n"), py::arg("i"), py::arg("j"), py::arg("k"),
        "Index of lattice particle (i, j, k) of an n x n x n cube: (i*n + j)*n + k.");

  py::class_<AnchorSpring>(m, "AnchorSpring",
                           "A spring from a particle to a point in space (a pull from outside the "
                           "model, as the viewer's mouse drag): f = -k (x_p - target) - c v_p.")
      .def(py::init([](int particle, const Vec3& target, Real stiffness, Real damping) {
             return AnchorSpring{particle, target, stiffness, damping};
           }),
           py::arg("particle"), py::arg("target"), py::arg("stiffness"), py::arg("damping") = 0.0,
           "An anchor of a particle to a target point (m) with stiffness k (N/m) and damping c "
           "(N s/m) on the particle's own velocity.")
      .def_readwrite("particle", &AnchorSpring::particle, "The particle's index.")
      .def_readwrite("target", &AnchorSpring::target, "The point it is pulled to (m).")
      .def_readwrite("stiffness", &AnchorSpring::stiffness, "k (N/m), >= 0.")
      .def_readwrite("damping", &AnchorSpring::damping, "c (N s/m), >= 0.")
      .def("__repr__", [](const AnchorSpring& a) {
        return "AnchorSpring(particle=" + std::to_string(a.particle) +
               ", stiffness=" + to_text(a.stiffness) + ", damping=" + to_text(a.damping) + ")";
      });

  m.def("kinetic_energy", py::overload_cast<const Model&, const State&>(&kinetic_energy),
        py::arg("model"), py::arg("state"), "sum m |v|^2 / 2 (J).");
  m.def("elastic_energy", py::overload_cast<const Model&, const State&>(&elastic_energy),
        py::arg("model"), py::arg("state"), "sum ks (|xa - xb| - l0)^2 / 2 (J).");
  m.def("gravitational_energy",
        py::overload_cast<const Model&, const State&>(&gravitational_energy), py::arg("model"),
        py::arg("state"), "-sum m g . x (J).");
  m.def("total_energy", &total_energy, py::arg("model"), py::arg("state"),
        "Kinetic + elastic + gravitational energy (J).");
  m.def("center_of_mass", py::overload_cast<const Model&, const State&>(&center_of_mass),
        py::arg("model"), py::arg("state"), "sum m x / sum m (m), [3].");
  m.def("linear_momentum", py::overload_cast<const Model&, const State&>(&linear_momentum),
        py::arg("model"), py::arg("state"), "sum m v (kg m/s), [3].");
  m.def("angular_momentum", py::overload_cast<const Model&, const State&>(&angular_momentum),
        py::arg("model"), py::arg("state"), "sum m x cross v about the origin (kg m^2/s), [3].");
}

}  // namespace jelly::python
