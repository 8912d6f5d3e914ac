// core/: the model (masses, springs as NumPy arrays, its bodies with their render surfaces,
// pins and external forces), the state, energies and momenta.
#include <map>
#include <optional>
#include <vector>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/force.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/pins.hpp>
#include <jelly/core/state.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

#include "common.hpp"
#include "fields.hpp"

namespace jelly::python {

namespace {

// The State argument of Body.x / Body.v: a TypeError naming the type given otherwise (an array
// of positions is a common mistake), not pybind11's "Unable to cast".
const State& body_state_argument(const py::object& state, const char* method) {
  if (!py::isinstance<State>(state)) {
    throw py::type_error(std::string("Body.") + method + "(state): state must be a jelly.State " +
                         "(sim.state, a snapshot's state), not " +
                         py::str(py::type::of(state).attr("__name__")).cast<std::string>());
  }
  return state.cast<const State&>();
}

// The positions of a State, or an (N, 3) / (3N,) array of them, as the flat vector they are
// in C++ (copied only for an array).
VecX positions_of(const py::object& x, const std::string& field) {
  if (py::isinstance<State>(x)) return x.cast<const State&>().x;
  return flat_n3(x.cast<DoubleArray>(), field);
}

// Rows [first, first + count) of a flat 3N vector as an (count, 3) view owned by `owner`.
py::array rows_view(const VecX& v, int first, int count, py::handle owner) {
  py::array a(py::dtype::of<Real>(), {py::ssize_t{count}, py::ssize_t{3}},
              {static_cast<py::ssize_t>(3 * sizeof(Real)), static_cast<py::ssize_t>(sizeof(Real))},
              v.data() + 3 * static_cast<py::ssize_t>(first), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

// The vertex positions of a surface for the positions of a State (or an array of them), a new
// (V, 3) array.
py::array vertices_of(const Surface& surface, const py::object& x) {
  const VecX flat = positions_of(x, "x");
  for (int p : surface.particles) {
    require(3 * static_cast<Eigen::Index>(p) + 2 < flat.size(), "x.size", flat.size() / 3,
            "the model's particles (the surface uses particle " + std::to_string(p) + ")");
  }
  RowMatrixX3 out;
  surface.vertices(flat, out);
  return py::array(py::cast(std::move(out)));
}

// A Force subclassed in Python: forces(self, t, x, v, f) adds into f ((N, 3), float64); the
// optional jacobians(self, t, x, v) returns (dfdx, dfdv), each a SciPy sparse matrix (anything
// with tocoo()), a dense (3N, 3N) array or None. Called from the stepping thread with the GIL
// released: each call takes it back. x and v are read-only copies; f starts at zero and is
// added to the simulator's forces.
class PyForce : public Force {
 public:
  std::string name() const override {
    py::gil_scoped_acquire gil;
    const py::object self = py::cast(static_cast<const Force*>(this));
    if (py::hasattr(self, "name") && py::isinstance<py::str>(self.attr("name")))
      return self.attr("name").cast<std::string>();
    return py::str(self.get_type().attr("__name__")).cast<std::string>();
  }
  void add_forces(Real t, const VecX& x, const VecX& v, VecX& f) const override {
    py::gil_scoped_acquire gil;
    const py::function forces = py::get_override(static_cast<const Force*>(this), "forces");
    if (!forces) throw InputError("jelly.Force subclasses must override forces(self, t, x, v, f)");
    const py::ssize_t n = x.size() / 3;
    py::array_t<Real> xa({n, py::ssize_t{3}}), va({n, py::ssize_t{3}}), fa({n, py::ssize_t{3}});
    std::copy(x.data(), x.data() + x.size(), xa.mutable_data());
    std::copy(v.data(), v.data() + v.size(), va.mutable_data());
    std::fill(fa.mutable_data(), fa.mutable_data() + f.size(), 0.0);
    for (py::array_t<Real>* a : {&xa, &va})
      py::detail::array_proxy(a->ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    forces(t, xa, va, fa);
    const Real* added = fa.data();
    for (Eigen::Index k = 0; k < f.size(); ++k) f[k] += added[k];
  }
  bool has_jacobian() const override {
    py::gil_scoped_acquire gil;
    return static_cast<bool>(py::get_override(static_cast<const Force*>(this), "jacobians"));
  }
  void add_jacobian(Real t, const VecX& x, const VecX& v, ForceJacobian& jacobian) const override {
    py::gil_scoped_acquire gil;
    const py::function jacobians = py::get_override(static_cast<const Force*>(this), "jacobians");
    if (!jacobians) return;
    const py::ssize_t n = x.size() / 3;
    py::array_t<Real> xa({n, py::ssize_t{3}}), va({n, py::ssize_t{3}});
    std::copy(x.data(), x.data() + x.size(), xa.mutable_data());
    std::copy(v.data(), v.data() + v.size(), va.mutable_data());
    const py::object result = jacobians(t, xa, va);
    if (result.is_none()) return;
    if (!py::isinstance<py::tuple>(result) || py::len(result) != 2)
      throw InputError("force '" + name() + "' jacobians()", py::repr(result).cast<std::string>(),
                       "a tuple (dfdx, dfdv) of sparse matrices, arrays or None");
    // Entries grouped into 3x3 blocks of particles, in a sorted map (deterministic order).
    std::map<std::pair<int, int>, ForceJacobian::Block> blocks;
    for (int which = 0; which < 2; ++which) {
      const py::object m = py::tuple(result)[which];
      if (m.is_none()) continue;
      const std::string field = "force '" + name() + "' jacobians()[" + std::to_string(which) + "]";
      const py::object coo = py::hasattr(m, "tocoo") ? m.attr("tocoo")() : py::object();
      std::vector<long> rows, cols;
      std::vector<Real> values;
      if (coo) {
        rows = py::cast<std::vector<long>>(coo.attr("row").attr("tolist")());
        cols = py::cast<std::vector<long>>(coo.attr("col").attr("tolist")());
        values = py::cast<std::vector<Real>>(coo.attr("data").attr("tolist")());
        const py::tuple shape = coo.attr("shape");
        require(shape[0].cast<long>() == 3 * n && shape[1].cast<long>() == 3 * n, field + " shape",
                py::repr(shape).cast<std::string>(), "(3N, 3N) with N = " + std::to_string(n));
      } else {
        const auto dense = py::array_t<Real, py::array::c_style | py::array::forcecast>::ensure(m);
        require(dense && dense.ndim() == 2 && dense.shape(0) == 3 * n && dense.shape(1) == 3 * n,
                field, py::repr(m).cast<std::string>().substr(0, 60),
                "a (3N, 3N) SciPy sparse matrix or array with N = " + std::to_string(n));
        for (long r = 0; r < 3 * n; ++r)
          for (long c = 0; c < 3 * n; ++c)
            if (const Real value = dense.at(r, c); value != 0) {
              rows.push_back(r);
              cols.push_back(c);
              values.push_back(value);
            }
      }
      for (std::size_t k = 0; k < values.size(); ++k) {
        require(rows[k] >= 0 && rows[k] < 3 * n && cols[k] >= 0 && cols[k] < 3 * n,
                field + " entry",
                "(" + std::to_string(rows[k]) + ", " + std::to_string(cols[k]) + ")",
                "indices in [0, 3N)");
        ForceJacobian::Block& b =
            blocks[{static_cast<int>(rows[k] / 3), static_cast<int>(cols[k] / 3)}];
        b.i = static_cast<int>(rows[k] / 3);
        b.j = static_cast<int>(cols[k] / 3);
        (which == 0 ? b.dfdx : b.dfdv)(rows[k] % 3, cols[k] % 3) += values[k];
      }
    }
    for (const auto& [at, b] : blocks) jacobian.add(b.i, b.j, b.dfdx, b.dfdv);
  }
};

// Model's pickled state: every field, as plain values (paths of pins as their scene JSON).
py::tuple surface_state(const Surface& s) {
  return py::make_tuple(s.triangles, s.offsets, s.particles, s.weights);
}

Surface surface_from_state(const py::tuple& t) {
  Surface s;
  s.triangles = t[0].cast<std::vector<Triangle>>();
  s.offsets = t[1].cast<std::vector<int>>();
  s.particles = t[2].cast<std::vector<int>>();
  s.weights = t[3].cast<std::vector<Real>>();
  return s;
}

py::tuple model_state(const Model& md) {
  const Springs& sp = md.springs;
  std::vector<int> types;
  for (SpringType t : sp.type) types.push_back(static_cast<int>(t));
  py::list bodies;
  for (const Body& b : md.bodies) {
    py::list groups;
    for (const ParticleGroup& g : b.groups) groups.append(py::make_tuple(g.name, g.particles));
    bodies.append(py::make_tuple(b.name, b.kind, b.first_particle, b.num_particles, b.first_spring,
                                 b.num_springs, b.spacing, b.radius, b.velocity, b.angular_velocity,
                                 surface_state(b.surface), groups, b.color, b.thickness));
  }
  std::vector<std::string> paths;
  for (const Path& p : md.pins.paths) paths.push_back(p.to_json().dump());
  py::list forces;
  for (const ExternalForce& f : md.external_forces) {
    forces.append(py::make_tuple(static_cast<int>(f.kind), f.particles, f.vector, f.drag, f.gust,
                                 f.gust_frequency, f.start, f.end));
  }
  return py::make_tuple(
      md.mass, md.rest_position, py::make_tuple(sp.a, sp.b, sp.rest_length, sp.ks, sp.kd, types),
      md.gravity, bodies, py::make_tuple(md.pins.particles, md.pins.anchors, md.pins.path, paths),
      forces);
}

Model model_from_state(const py::tuple& t) {
  require(t.size() == 7, "Model state", std::to_string(t.size()) + " items",
          "the 7 items of a pickled Model");
  Model md;
  md.mass = t[0].cast<VecX>();
  md.rest_position = t[1].cast<VecX>();
  const auto sp = t[2].cast<py::tuple>();
  md.springs.a = sp[0].cast<std::vector<int>>();
  md.springs.b = sp[1].cast<std::vector<int>>();
  md.springs.rest_length = sp[2].cast<std::vector<Real>>();
  md.springs.ks = sp[3].cast<std::vector<Real>>();
  md.springs.kd = sp[4].cast<std::vector<Real>>();
  for (int type : sp[5].cast<std::vector<int>>()) {
    require(type >= 0 && type < kSpringTypeCount, "Model state spring type", type, "0, 1 or 2");
    md.springs.type.push_back(static_cast<SpringType>(type));
  }
  md.gravity = t[3].cast<Vec3>();
  for (const py::handle item : t[4].cast<py::list>()) {
    const auto b = item.cast<py::tuple>();
    Body body;
    body.name = b[0].cast<std::string>();
    body.kind = b[1].cast<std::string>();
    body.first_particle = b[2].cast<int>();
    body.num_particles = b[3].cast<int>();
    body.first_spring = b[4].cast<int>();
    body.num_springs = b[5].cast<int>();
    body.spacing = b[6].cast<Real>();
    body.radius = b[7].cast<Real>();
    body.velocity = b[8].cast<Vec3>();
    body.angular_velocity = b[9].cast<Vec3>();
    body.surface = surface_from_state(b[10].cast<py::tuple>());
    for (const py::handle g : b[11].cast<py::list>()) {
      const auto group = g.cast<py::tuple>();
      body.groups.push_back({group[0].cast<std::string>(), group[1].cast<std::vector<int>>()});
    }
    body.color = b[12].cast<std::optional<Vec3>>();
    // (A Model pickled before bodies had a thickness: the default of its kind.)
    if (b.size() > 13)
      body.thickness = b[13].cast<Real>();
    else
      body.thickness = body.kind == "cloth" ? body.radius : 0;
    md.bodies.push_back(std::move(body));
  }
  const auto pins = t[5].cast<py::tuple>();
  md.pins.particles = pins[0].cast<std::vector<int>>();
  md.pins.anchors = pins[1].cast<std::vector<Vec3>>();
  md.pins.path = pins[2].cast<std::vector<int>>();
  for (const std::string& text : pins[3].cast<std::vector<std::string>>())
    md.pins.paths.push_back(Path::read(Json::parse(text), "Model state pin path"));
  for (const py::handle item : t[6].cast<py::list>()) {
    const auto f = item.cast<py::tuple>();
    ExternalForce force;
    const int kind = f[0].cast<int>();
    require(kind >= 0 && kind <= static_cast<int>(ExternalForceKind::kPoint),
            "Model state external force kind", kind, "0, 1 or 2");
    force.kind = static_cast<ExternalForceKind>(kind);
    force.particles = f[1].cast<std::vector<int>>();
    force.vector = f[2].cast<Vec3>();
    force.drag = f[3].cast<Real>();
    force.gust = f[4].cast<Real>();
    force.gust_frequency = f[5].cast<Real>();
    force.start = f[6].cast<Real>();
    force.end = f[7].cast<Real>();
    md.external_forces.push_back(std::move(force));
  }
  md.validate();  // a tampered pickle is an InputError, not a broken model
  return md;
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

  py::class_<SpringCoefficients> spring_coefficients(
      m, "SpringCoefficients", "Stiffness ks (N/m) and damping kd (N s/m) of one spring type.");
  def_fields(spring_coefficients, spring_fields(), "springs.structural");
  spring_coefficients
      .def(py::init([](Real ks, Real kd) {
             return SpringCoefficients{ks, kd};
           }),
           py::arg("ks") = 1400, py::arg("kd") = 50, "Coefficients ks (N/m) and kd (N s/m).")
      .def("__repr__", [](const SpringCoefficients& c) {
        return "SpringCoefficients(ks=" + to_text(c.ks) + ", kd=" + to_text(c.kd) + ")";
      });

  py::class_<Springs>(m, "Springs",
                      "Springs stored once each as parallel arrays (read-only NumPy views of the "
                      "C++ memory; other coefficients: a scene with them, or build_cube).")
      .def("__repr__",
           [](const Springs& sp) {
             return "<jelly.Springs " + std::to_string(sp.size()) + " springs>";
           })
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

  py::class_<Surface>(m, "Surface",
                      "The triangle surface a person sees of a body: vertex v is the weighted sum "
                      "of particle positions sum_k weights[k] x[particles[k]] for k in "
                      "[offsets[v], offsets[v+1]); triangles are counter-clockwise seen from "
                      "outside. Arrays are read-only views of the C++ memory; particle indices "
                      "are the model's (global).")
      .def_property_readonly(
          "triangles",
          [](py::object self) {
            const Surface& s = self.cast<const Surface&>();
            static_assert(sizeof(Triangle) == 3 * sizeof(int));
            py::array a(
                py::dtype::of<int>(), {py::ssize_t{s.num_triangles()}, py::ssize_t{3}},
                {static_cast<py::ssize_t>(sizeof(Triangle)), static_cast<py::ssize_t>(sizeof(int))},
                s.triangles.empty() ? nullptr : s.triangles.front().data(), self);
            py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return a;
          },
          "Vertex indices of each triangle, int32 [T, 3].")
      .def_property_readonly(
          "offsets",
          [](py::object self) {
            const Surface& s = self.cast<const Surface&>();
            return view(s.offsets.data(), static_cast<py::ssize_t>(s.offsets.size()), self);
          },
          "Where each vertex's particles and weights start, int32 [V + 1].")
      .def_property_readonly(
          "particles",
          [](py::object self) {
            const Surface& s = self.cast<const Surface&>();
            return view(s.particles.data(), static_cast<py::ssize_t>(s.particles.size()), self);
          },
          "The particles of the vertices' weighted sums, int32.")
      .def_property_readonly(
          "weights",
          [](py::object self) {
            const Surface& s = self.cast<const Surface&>();
            return view(s.weights.data(), static_cast<py::ssize_t>(s.weights.size()), self);
          },
          "The weights of the vertices' weighted sums, float64.")
      .def_property_readonly("num_vertices", &Surface::num_vertices, "The number of vertices V.")
      .def_property_readonly("num_triangles", &Surface::num_triangles, "The number of triangles T.")
      .def("vertices", &vertices_of, py::arg("x"),
           "The vertex positions (m), a new float64 [V, 3] array, for the positions of a State "
           "(or an (N, 3) array of the whole model's particles).")
      .def("__len__", &Surface::num_triangles, "The number of triangles.")
      .def("__repr__", [](const Surface& s) {
        return "<jelly.Surface with " + std::to_string(s.num_vertices()) + " vertices and " +
               std::to_string(s.num_triangles()) + " triangles>";
      });

  py::class_<Body>(m, "Body",
                   "A body of the model: a named range of its particles and springs (kind "
                   "\"cube\", \"box\", \"cloth\", ...: jelly.body_kinds()) with its render "
                   "surface. Scenes describe bodies in their \"bodies\" list.")
      .def_readonly("name", &Body::name, "Unique in the model (the HDF5 group /particles/<name>).")
      .def_readonly("kind", &Body::kind, "The body kind that built it.")
      .def_readonly("first_particle", &Body::first_particle, "Its first particle's index.")
      .def_readonly("num_particles", &Body::num_particles, "Its number of particles.")
      .def_readonly("first_spring", &Body::first_spring, "Its first spring's index.")
      .def_readonly("num_springs", &Body::num_springs, "Its number of springs.")
      .def_readonly("spacing", &Body::spacing,
                    "Typical distance between neighbouring particles (m).")
      .def_readonly("radius", &Body::radius, "Contact radius of its particles (m).")
      .def_readonly("thickness", &Body::thickness,
                    "The distance its particles keep from terrains and obstacles (m): the scene "
                    "key thickness; by default the contact radius for a cloth, 0 for a body "
                    "with volume.")
      .def_readonly("color", &Body::color,
                    "Its colour in pictures and exports: the scene key color, sRGB [r, g, b] "
                    "in [0, 1], or None (the viewer's palette by body index).")
      .def_property_readonly(
          "particles",
          [](const Body& b) {
            return py::module_::import("builtins")
                .attr("range")(b.first_particle, b.end_particle());
          },
          "Its particle indices, range(first_particle, first_particle + num_particles): "
          "state.x[body.particles] are its positions.")
      .def_property_readonly(
          "springs",
          [](const Body& b) {
            return py::module_::import("builtins").attr("range")(b.first_spring, b.end_spring());
          },
          "Its spring indices, a range into model.springs' arrays.")
      .def_property_readonly(
          "surface", [](const Body& b) -> const Surface& { return b.surface; },
          py::return_value_policy::reference_internal,
          "Its render Surface (triangles over vertices that follow the particles).")
      .def_property_readonly(
          "groups",
          [](py::object self) {
            py::dict d;
            for (const ParticleGroup& g : self.cast<const Body&>().groups) {
              d[py::str(g.name)] =
                  view(g.particles.data(), static_cast<py::ssize_t>(g.particles.size()), self);
            }
            return d;
          },
          "Named particle groups (a cloth's corners, ...) as {name: int32 array of global "
          "indices}.")
      .def("contains", &Body::contains, py::arg("particle"), "Whether it holds particle i.")
      .def(
          "x",
          [](const Body& b, py::object state) {
            const State& s = body_state_argument(state, "x");
            require(b.end_particle() <= s.x.size() / 3, "state.num_particles", s.x.size() / 3,
                    "at least " + std::to_string(b.end_particle()) + " (body " + b.name + ")");
            return rows_view(s.x, b.first_particle, b.num_particles, state);
          },
          py::arg("state"),
          "Its particles' positions in a State, a read-only (num_particles, 3) view (no copy).")
      .def(
          "v",
          [](const Body& b, py::object state) {
            const State& s = body_state_argument(state, "v");
            require(b.end_particle() <= s.v.size() / 3, "state.num_particles", s.v.size() / 3,
                    "at least " + std::to_string(b.end_particle()) + " (body " + b.name + ")");
            return rows_view(s.v, b.first_particle, b.num_particles, state);
          },
          py::arg("state"),
          "Its particles' velocities in a State, a read-only (num_particles, 3) view (no copy).")
      .def(
          "surface_vertices",
          [](const Body& b, const py::object& x) { return vertices_of(b.surface, x); },
          py::arg("x"),
          "Its render surface's vertex positions (m), a new float64 [V, 3] array, for the "
          "positions of a State (or an (N, 3) array of the whole model's particles).")
      .def("__repr__", [](const Body& b) {
        return "<jelly.Body '" + b.name + "' (" + b.kind + ") particles [" +
               std::to_string(b.first_particle) + ", " + std::to_string(b.end_particle()) + "), " +
               std::to_string(b.surface.num_triangles()) + " surface triangles>";
      });

  py::class_<Pins>(m, "Pins",
                   "Pinned particles: held at their anchor or moved along a prescribed path; "
                   "every integrator honours them exactly.")
      .def_property_readonly(
          "particles",
          [](py::object self) {
            const Pins& p = self.cast<const Pins&>();
            return view(p.particles.data(), static_cast<py::ssize_t>(p.particles.size()), self);
          },
          "The pinned particles' global indices, int32 [P].")
      .def_property_readonly(
          "anchors",
          [](const Pins& p) {
            RowMatrixX3 a(p.size(), 3);
            for (int k = 0; k < p.size(); ++k) a.row(k) = p.anchors[k].transpose();
            return a;
          },
          "Their positions at t = 0 (m), a copy [P, 3].")
      .def(
          "positions",
          [](const Pins& p, Real t) {
            RowMatrixX3 a(p.size(), 3);
            for (int k = 0; k < p.size(); ++k) a.row(k) = p.position(k, t).transpose();
            return a;
          },
          py::arg("t"), "Where their paths put them at time t (m), [P, 3].")
      .def_property_readonly("all_fixed", &Pins::all_fixed, "Whether no pin moves.")
      .def("__len__", &Pins::size, "The number of pinned particles.")
      .def("__repr__", [](const Pins& p) {
        return "<jelly.Pins " + std::to_string(p.size()) + " particles, " +
               std::to_string(p.paths.size()) + " paths>";
      });

  py::class_<ExternalForce>(m, "ExternalForce",
                            "A force from outside the bodies (a scene body's \"forces\"): "
                            "constant (N, spread by mass), wind (drag towards the air's "
                            "velocity) or point (N on each particle), with an optional gust and "
                            "time window.")
      .def_property_readonly(
          "kind",
          [](const ExternalForce& f) { return std::string(external_force_kind_name(f.kind)); },
          "\"constant\", \"wind\" or \"point\".")
      .def_property_readonly(
          "particles",
          [](py::object self) {
            const ExternalForce& f = self.cast<const ExternalForce&>();
            return view(f.particles.data(), static_cast<py::ssize_t>(f.particles.size()), self);
          },
          "The global indices of the particles it acts on, int32.")
      .def_readonly("vector", &ExternalForce::vector, "Force (N) or, for wind, air velocity (m/s).")
      .def_readonly("drag", &ExternalForce::drag, "Wind: N s/m per particle.")
      .def_readonly("gust", &ExternalForce::gust, "vector(t) = vector (1 + gust sin(2 pi f t)).")
      .def_readonly("gust_frequency", &ExternalForce::gust_frequency, "f (Hz).")
      .def_readonly("start", &ExternalForce::start, "It acts for start <= t < end (s).")
      .def_readonly("end", &ExternalForce::end, "See start (s; inf = for ever).")
      .def("vector_at", &ExternalForce::vector_at, py::arg("t"), "vector(t).")
      .def("__repr__", [](const ExternalForce& f) {
        return "<jelly.ExternalForce " + std::string(external_force_kind_name(f.kind)) + " on " +
               std::to_string(f.particles.size()) + " particles>";
      });

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
      .def_property_readonly(
          "bodies",
          [](py::object self) {
            py::list out;
            for (const Body& b : self.cast<const Model&>().bodies) {
              out.append(py::cast(&b, py::return_value_policy::reference_internal, self));
            }
            return out;
          },
          "Its bodies in particle order (Body; views alive with the model).")
      .def(
          "body",
          [](py::object self, const std::string& name) {
            const Model& md = self.cast<const Model&>();
            const Body* b = md.find_body(name);
            if (!b) {
              std::string names;
              for (const Body& other : md.bodies) names += (names.empty() ? "" : ", ") + other.name;
              throw py::key_error("the model has no body '" + name + "'; its bodies: " + names);
            }
            return py::cast(b, py::return_value_policy::reference_internal, self);
          },
          py::arg("name"), "The body of that name (KeyError listing the names otherwise).")
      .def(
          "body_of",
          [](py::object self, int particle) {
            const Model& md = self.cast<const Model&>();
            require(particle >= 0 && particle < md.num_particles(), "particle", particle,
                    "an index in [0, " + std::to_string(md.num_particles()) + ")");
            return py::cast(&md.body_of(particle), py::return_value_policy::reference_internal,
                            self);
          },
          py::arg("particle"), "The body that holds a particle.")
      .def_property_readonly(
          "pins", [](const Model& md) -> const Pins& { return md.pins; },
          py::return_value_policy::reference_internal, "The pinned particles (Pins).")
      .def_property_readonly(
          "external_forces",
          [](py::object self) {
            py::list out;
            for (const ExternalForce& f : self.cast<const Model&>().external_forces) {
              out.append(py::cast(&f, py::return_value_policy::reference_internal, self));
            }
            return out;
          },
          "Forces from outside the bodies (ExternalForce), besides gravity.")
      .def_property_readonly("num_particles", &Model::num_particles, "The number of particles N.")
      .def_property_readonly(
          "num_springs", [](const Model& md) { return md.springs.size(); },
          "The number of springs M.")
      .def("validate", &Model::validate,
           "Raises InputError when a mass, index, rest length or coefficient is out of range.")
      .def(py::pickle(&model_state, &model_from_state))
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

  m.def("rest_state", &rest_state, py::arg("model"),
        "The model at rest in its construction pose, at t = 0.");
  m.def("initial_state", &initial_state, py::arg("model"),
        "The model in its construction pose at t = 0, each body moving with its scene's "
        "velocity and angular_velocity (at rest when they are zero).");
  py::class_<Force, PyForce, std::shared_ptr<Force>>(
      m, "Force",
      "A force of your own, evaluated at every force evaluation of every integrator (each RK4 "
      "stage, each Newton iteration). Subclass it: override forces(self, t, x, v, f), which adds "
      "the force at time t on positions x and velocities v ((N, 3) read-only arrays) into f "
      "((N, 3), in place); optionally jacobians(self, t, x, v) returning (dfdx, dfdv), each a "
      "(3N, 3N) SciPy sparse matrix, a dense array or None, which implicit_euler takes into its "
      "solve (without them it treats the force explicitly within its step and the run report's "
      "notes say so). An optional str attribute `name` names it in messages. Add it with "
      "Simulator.add_force; an exception raised in it stops the run with that exception, the "
      "simulator left at the last completed step.")
      .def(py::init<>(), "A force; override forces (and optionally jacobians).")
      .def(
          "forces",
          [](const Force&, Real, const py::object&, const py::object&, const py::object&) {
            throw InputError("jelly.Force subclasses must override forces(self, t, x, v, f)");
          },
          py::arg("t"), py::arg("x"), py::arg("v"), py::arg("f"),
          "Adds the force at time t on positions x and velocities v ((N, 3), read-only) into f "
          "((N, 3), in place). Override it.")
      .def(
          "jacobians",
          [](const Force&, Real, const py::object&, const py::object&) { return py::none(); },
          py::arg("t"), py::arg("x"), py::arg("v"),
          "(dfdx, dfdv) at (t, x, v), each a (3N, 3N) SciPy sparse matrix, a dense array or "
          "None; None (this default) when the force gives no Jacobians. Override it to give "
          "them.")
      .def(
          "check_jacobians",
          [](const Force& f, Real t, const DoubleArray& x, const DoubleArray& v, Real step) {
            VecX xv(x.size()), vv(v.size());
            assign_n3(xv, x, "x");
            assign_n3(vv, v, "v");
            const JacobianCheck c = check_force_jacobian(f, t, xv, vv, step);
            return py::make_tuple(c.dfdx_error, c.dfdv_error);
          },
          py::arg("t"), py::arg("x"), py::arg("v"), py::arg("step") = 1e-6,
          "The relative errors (dfdx, dfdv) of jacobians() against central differences of "
          "forces() at (t, x, v): the largest entry of |J - J_fd| over the largest of |J_fd| "
          "(dense: for small models).");

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
