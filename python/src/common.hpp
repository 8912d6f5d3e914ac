#pragma once
// Shared by the binding files of the Python module `jelly`: NumPy views of C++ memory and the
// conversion of NumPy input into flat 3N vectors. One binding file per C++ module folder.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <mutex>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/types.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/terrain/terrain.hpp>

namespace jelly::python {

namespace py = pybind11;

// A NumPy array over `count` values at `data`, owned by `owner` (which the array keeps alive).
// Read-only unless `writeable`: the C++ side may cache derived data, so writes go through
// explicit setters.
template <typename T>
py::array view(const T* data, py::ssize_t count, py::handle owner, bool writeable = false) {
  py::array a(py::dtype::of<T>(), {count}, {static_cast<py::ssize_t>(sizeof(T))}, data, owner);
  if (!writeable)
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

// The default (0, 0, 0) of a Vec3 argument, as a tuple: a Vec3 default would be converted to a
// NumPy array when the module is imported, importing NumPy with it (most of `import jelly`'s
// start-up); the tuple becomes a Vec3 when a call leaves the argument out.
inline py::tuple zero_vec3_default() { return py::make_tuple(0.0, 0.0, 0.0); }

// A flat 3N vector seen as an (N, 3) array without copying.
inline py::array view_n3(const VecX& v, py::handle owner, bool writeable = false) {
  const py::ssize_t n = v.size() / 3;
  py::array a(py::dtype::of<Real>(), {n, py::ssize_t{3}},
              {static_cast<py::ssize_t>(3 * sizeof(Real)), static_cast<py::ssize_t>(sizeof(Real))},
              v.data(), owner);
  if (!writeable)
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Copies an (N, 3) or flat (3N,) array into `out`, whose size (3N) must not change. Throws
// InputError naming `field` for another shape.
inline void assign_n3(VecX& out, const DoubleArray& in, const std::string& field) {
  const py::ssize_t size = in.size();
  const bool shape_ok = (in.ndim() == 2 && in.shape(1) == 3) || in.ndim() == 1;
  if (!shape_ok || size != out.size()) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < in.ndim(); ++d)
      shape += (d ? ", " : "") + std::to_string(in.shape(d));
    shape += in.ndim() == 1 ? ",)" : ")";
    throw InputError(field, "an array of shape " + shape,
                     "an array of shape (" + std::to_string(out.size() / 3) + ", 3) or (" +
                         std::to_string(out.size()) + ",)");
  }
  std::copy(in.data(), in.data() + size, out.data());
}

// An (N, 3) or (3N,) array as a new flat 3N vector.
inline VecX flat_n3(const DoubleArray& in, const std::string& field) {
  if (!((in.ndim() == 2 && in.shape(1) == 3) || (in.ndim() == 1 && in.size() % 3 == 0))) {
    throw InputError(field, "an array of " + std::to_string(in.ndim()) + " dimension(s)",
                     "an array of shape (N, 3) or (3N,)");
  }
  VecX out(in.size());
  std::copy(in.data(), in.data() + in.size(), out.data());
  return out;
}

// A recording read from HDF5, with its per-frame vectors as NumPy arrays [T, N, 3] built on
// first use (io.cpp binds it as jelly.Recording; fit.cpp fits one).
struct PyRecording {
  Recording recording;
  std::string path;  // absolute; pickles by it
  py::object position, velocity;
};

// A spring type from a SpringType or its name ("structural", "shear", "bending").
inline SpringType spring_type_from(const py::object& type) {
  if (py::isinstance<py::str>(type)) {
    const std::string name = type.cast<std::string>();
    for (int t = 0; t < kSpringTypeCount; ++t) {
      if (spring_type_name(static_cast<SpringType>(t)) == name) return static_cast<SpringType>(t);
    }
    throw InputError("spring type", "\"" + name + "\"", "\"structural\", \"shear\" or \"bending\"");
  }
  return type.cast<SpringType>();
}

// A terrain of any registered kind from its scene JSON (a dict or JSON text), validated with
// messages naming "terrain.<field>" (terrain.cpp).
std::unique_ptr<Terrain> terrain_from_spec(const py::object& spec);

// Holds the lock of a Python Simulator object (threads.cpp) for its scope: every call that
// reads or changes a simulator takes it, so that calls from several threads run one after the
// other. Waits with the GIL released; the same thread may take it again (a callback of
// run_until calling the simulator).
class SimulatorLock {
 public:
  explicit SimulatorLock(py::handle simulator);
  ~SimulatorLock();
  SimulatorLock(const SimulatorLock&) = delete;
  SimulatorLock& operator=(const SimulatorLock&) = delete;

 private:
  py::object holder_;  // keeps the lock alive
  std::recursive_mutex* mutex_;
};

// Makes every method and property of jelly.Simulator (and the module functions that take a
// simulator) take its SimulatorLock; called by module.cpp after every binding is made.
void serialise_simulator(py::module_& m);

// One binding function per C++ module folder, called in layer order by module.cpp.
void bind_core(py::module_& m);
void bind_geometry(py::module_& m);
void bind_terrain(py::module_& m);
void bind_solvers(py::module_& m);
void bind_io(py::module_& m);
void bind_fit(py::module_& m);
void bind_adjoint(py::module_& m);
// DLPack export of arrays (dlpack.cpp).
void bind_dlpack(py::module_& m);

}  // namespace jelly::python
