// terrain/: obstacles (plane, slope, elevator) and their contact parameters. A Simulator takes a
// copy of a terrain (Simulator.add_terrain); scenes name terrains in their JSON instead.
#include <jelly/terrain/contact_params.hpp>
#include <jelly/terrain/elevator.hpp>
#include <jelly/terrain/plane.hpp>
#include <jelly/terrain/terrain.hpp>

#include "common.hpp"

namespace jelly::python {

void bind_terrain(py::module_& m) {
  py::class_<ContactParams>(m, "ContactParams",
                            "How a terrain answers a particle that touches it (docs/contact.md).")
      .def(py::init<>(), "The defaults: coulomb, restitution 0.8, friction 0.5.")
      .def_property(
          "model", [](const ContactParams& c) { return std::string(contact_model_name(c.model)); },
          [](ContactParams& c, const std::string& name) {
            c.model = contact_model_from_name(name, "contact.model");
          },
          "\"coulomb\" or \"seed\".")
      .def_readwrite("restitution", &ContactParams::restitution, "In [0, 1].")
      .def_readwrite("friction", &ContactParams::friction,
                     "Kinetic mu (coulomb), the report's friction (seed).")
      .def_readwrite("static_friction", &ContactParams::static_friction, "Coulomb: >= friction.")
      .def_readwrite("epsilon", &ContactParams::epsilon, "Seed: contact distance (m).")
      .def_readwrite("resting_speed", &ContactParams::resting_speed,
                     "Coulomb: slowest approach that bounces (m/s).")
      .def(
          "validate", [](const ContactParams& c) { c.validate("contact."); },
          "Raises InputError naming the first invalid field.");

  py::class_<Terrain>(m, "Terrain", "A rigid obstacle moving as a prescribed function of time.")
      .def_property_readonly(
          "kind", [](const Terrain& t) { return std::string(t.kind()); },
          "\"plane\", \"elevator\", ...")
      .def("signed_distance", &Terrain::signed_distance, py::arg("p"), py::arg("t"),
           "Distance of point p above the surface at time t (m): > 0 outside.")
      .def("normal", &Terrain::normal, py::arg("p"), py::arg("t"),
           "Outward unit normal of the surface nearest p.")
      .def("surface_velocity", &Terrain::surface_velocity, py::arg("p"), py::arg("t"),
           "Velocity of the surface point nearest p (m/s).")
      .def("position", &Terrain::position, py::arg("t"),
           "A reference point moving with the terrain (what recordings store).")
      .def_property_readonly("mass", &Terrain::mass, "Mass in the seed collision formula (kg).")
      .def_property("contact", &Terrain::contact, &Terrain::set_contact,
                    "Its ContactParams (a copy).");

  py::class_<Plane, Terrain>(m, "Plane", "A fixed infinite plane (half-space): a floor or a slope.")
      .def(py::init<const Vec3&, const Vec3&, ContactParams>(), py::arg("point"), py::arg("normal"),
           py::arg("contact") = ContactParams{},
           "The plane through point with outward normal (any non-zero length).")
      .def_static("slope", &Plane::slope, py::arg("angle_degrees"), py::arg("point") = Vec3::Zero(),
                  py::arg("contact") = ContactParams{},
                  "The plane through point tilted by angle_degrees about z: normal (sin a, cos a, "
                  "0). The seed slope is Plane.slope(20).")
      .def_property_readonly("point", &Plane::point, "A point of the plane.")
      .def_property_readonly("unit_normal", &Plane::unit_normal, "Its outward unit normal.");

  py::class_<ElevatorSpec>(m, "ElevatorSpec",
                           "The seed elevator's platform; its motion is the seed cycle.")
      .def(py::init<>(), "The seed elevator: 5 x 5 m at y = 1, mass 1, the seed motion.")
      .def_readwrite("center", &ElevatorSpec::center, "Platform centre at t = 0 (m).")
      .def_readwrite("size_x", &ElevatorSpec::size_x, "Footprint along x (m).")
      .def_readwrite("size_z", &ElevatorSpec::size_z, "Footprint along z (m).")
      .def_readwrite("thickness", &ElevatorSpec::thickness,
                     "Depth below the surface that still touches (m).")
      .def_readwrite("mass", &ElevatorSpec::mass,
                     "Platform mass of the seed formula (kg; inf = immovable).")
      .def(
          "validate", [](const ElevatorSpec& s) { s.validate(); },
          "Raises InputError naming the first invalid field.");

  py::class_<Elevator, Terrain>(m, "Elevator", "The seed elevator: a platform moving vertically.")
      .def(py::init<ElevatorSpec, ContactParams>(), py::arg("spec") = ElevatorSpec{},
           py::arg("contact") = ContactParams{},
           "An elevator from its spec and contact parameters.")
      .def("height", &Elevator::height, py::arg("t"), "Platform height at time t (m).")
      .def_property_readonly("spec", &Elevator::spec, "Its ElevatorSpec (a copy).");
}

}  // namespace jelly::python
