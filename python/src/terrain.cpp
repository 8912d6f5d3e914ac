// terrain/: obstacles (plane, slope, elevator, and every kind of the registry from its scene
// JSON) and their contact parameters. A Simulator takes a copy of a Plane or an Elevator, or
// builds any kind from its spec (Simulator.add_terrain); scenes name terrains in their JSON.
#include <Eigen/Geometry>

#include <jelly/core/detail/json.hpp>
#include <jelly/terrain/detail/contact_fields.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/detail/terrain_fields.hpp>
#include <jelly/terrain/plane.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

#include "common.hpp"
#include "fields.hpp"

namespace jelly::python {

std::unique_ptr<Terrain> terrain_from_spec(const py::object& spec) {
  const std::string field = "terrain";
  if (py::isinstance<Terrain>(spec)) {
    throw InputError(field, "a " + std::string(spec.cast<const Terrain&>().kind()) + " terrain",
                     "a Plane, an Elevator, or the spec of a terrain (a dict or JSON text) for "
                     "the other kinds");
  }
  std::string text;
  if (py::isinstance<py::str>(spec)) {
    text = spec.cast<std::string>();
  } else {
    text = py::module_::import("json").attr("dumps")(spec).cast<std::string>();
  }
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::exception&) {
    throw InputError(field, "\"" + text.substr(0, 60) + "\"",
                     "a terrain object as a dict or JSON text, {\"kind\": ..., ...}");
  }
  return read_terrain_spec(j, field)->make();
}

void bind_terrain(py::module_& m) {
  m.def(
      "terrain_kinds",
      [] {
        py::dict d;
        for (const TerrainKindInfo& k : terrain_kinds()) {
          d[py::str(std::string(k.name))] = std::string(k.description);
        }
        return d;
      },
      "Every terrain kind a scene's \"terrains\" (or make_terrain) can name, as {name: "
      "description with its keys}, sorted by name.");
  m.def(
      "contact_models",
      [] {
        py::dict d;
        for (const auto& c : contact_models()) {
          d[py::str(std::string(c.name))] = std::string(c.description);
        }
        return d;
      },
      "Every contact model a terrain's contact.model can name, as {name: description}.");
  py::class_<ContactParams> contact(
      m, "ContactParams", "How a terrain answers a particle that touches it (docs/contact.md).");
  contact.def(py::init<>(), "The defaults: coulomb, restitution 0.8, friction 0.5.");
  def_fields(contact, contact_params_fields(), "contact");
  contact.def(
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
      .def(
          "render_mesh",
          [](const Terrain& t) {
            const TriangleMesh mesh = t.render_mesh();
            RowMatrixX3 vertices(mesh.num_vertices(), 3);
            for (int v = 0; v < mesh.num_vertices(); ++v) vertices.row(v) = mesh.vertices[v];
            Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> triangles(mesh.num_triangles(),
                                                                             3);
            for (int k = 0; k < mesh.num_triangles(); ++k) {
              for (int c = 0; c < 3; ++c) triangles(k, c) = mesh.triangles[k][c];
            }
            return py::make_tuple(vertices, triangles);
          },
          "Its shape for drawing, in its own frame: (vertices float64 [V, 3], triangles int32 "
          "[T, 3], counter-clockwise seen from outside); pose(t) places it in the world.")
      .def(
          "pose",
          [](const Terrain& t, Real time) { return Eigen::Matrix4d(t.pose(time).matrix()); },
          py::arg("t"),
          "Where render_mesh() is at time t: a 4 x 4 rigid transform (world = pose @ [v, 1]).")
      .def(
          "attributes",
          [](const Terrain& t) {
            py::dict d;
            for (const auto& [name, value] : t.attributes()) d[py::str(name)] = value;
            return d;
          },
          "The kind's dimensions as {name: number} (what a recording stores).")
      .def("__repr__",
           [](const Terrain& t) { return "<jelly.Terrain " + std::string(t.kind()) + ">"; })
      .def_property(
          "contact", [](const Terrain& t) { return ContactParams(t.contact()); },
          &Terrain::set_contact,
          "Its ContactParams (a copy: writing to its fields changes nothing; assigning a whole "
          "ContactParams validates it and replaces the terrain's).");

  m.def("make_terrain", &terrain_from_spec, py::arg("spec"),
        "A terrain of any kind (terrain_kinds()) from its scene JSON: a dict or JSON text such "
        "as {\"kind\": \"sphere\", \"center\": [0, 1, 0], \"radius\": 1, \"contact\": "
        "{...}}. Raises InputError naming the field (terrain.radius).");

  py::class_<Plane, Terrain>(m, "Plane", "A fixed infinite plane (half-space): a floor or a slope.")
      .def(py::init<const Vec3&, const Vec3&, ContactParams>(), py::arg("point"), py::arg("normal"),
           py::arg("contact") = ContactParams{},
           "The plane through point with outward normal (any non-zero length).")
      .def_static("slope", &Plane::slope, py::arg("angle_degrees"),
                  py::arg("point") = zero_vec3_default(), py::arg("contact") = ContactParams{},
                  "The plane through point tilted by angle_degrees about z: normal (sin a, cos a, "
                  "0). The seed slope is Plane.slope(20).")
      .def_property_readonly("point", &Plane::point, "A point of the plane.")
      .def_property_readonly("unit_normal", &Plane::unit_normal, "Its outward unit normal.");

  py::class_<ElevatorSpec> elevator(m, "ElevatorSpec",
                                    "The seed elevator's platform; its motion is the seed cycle.");
  def_fields(elevator, elevator_fields(), "elevator");
  elevator.def(py::init<>(), "The seed elevator: 5 x 5 m at y = 1, mass 1, the seed motion.")
      .def(
          "validate", [](const ElevatorSpec& s) { s.validate("elevator."); },
          "Raises InputError naming the first invalid field.");

  py::class_<Elevator, Terrain>(m, "Elevator", "The seed elevator: a platform moving vertically.")
      .def(py::init<ElevatorSpec, ContactParams>(), py::arg("spec") = ElevatorSpec{},
           py::arg("contact") = ContactParams{},
           "An elevator from its spec and contact parameters.")
      .def("height", &Elevator::height, py::arg("t"), "Platform height at time t (m).")
      .def_property_readonly(
          "spec", [](const Elevator& e) { return ElevatorSpec(e.spec()); },
          "Its ElevatorSpec (a copy: writing to it changes nothing).");
}

}  // namespace jelly::python
