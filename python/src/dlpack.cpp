// DLPack export of the module's arrays without copies (torch.from_dlpack, jax.dlpack,
// numpy.from_dlpack): NumPy 1.24 refuses to export a read-only array (its DLPack has no
// read-only flag), and the views of a simulator's state are read-only. jelly.dlpack(array)
// wraps any CPU array (a read-only view included) in an object with __dlpack__ and
// __dlpack_device__ whose tensor keeps the array, and so its owner, alive.
#include <cstdint>
#include <string>
#include <vector>

#include "common.hpp"

#ifdef JELLY_HAVE_DLPACK
#include <dlpack/dlpack.h>
#endif

namespace jelly::python {

namespace {

#ifdef JELLY_HAVE_DLPACK
constexpr const char* kCapsuleName = "dltensor";
constexpr const char* kUsedCapsuleName = "used_dltensor";

// What a tensor handed out owns: the array (a strong reference) and the shape and strides the
// DLTensor points to.
struct Exported {
  DLManagedTensor tensor{};
  PyObject* array = nullptr;
  std::vector<std::int64_t> shape, strides;
};

void delete_exported(DLManagedTensor* tensor) {
  auto* e = static_cast<Exported*>(tensor->manager_ctx);
  // The consumer may call this from any thread, with or without the GIL.
  py::gil_scoped_acquire gil;
  Py_XDECREF(e->array);
  delete e;
}

DLDataType dl_type_of(const py::dtype& dtype) {
  const char kind = dtype.kind();
  const auto bits = static_cast<std::uint8_t>(8 * dtype.itemsize());
  if (kind == 'f') return {kDLFloat, bits, 1};
  if (kind == 'i') return {kDLInt, bits, 1};
  if (kind == 'u') return {kDLUInt, bits, 1};
  if (kind == 'b') return {kDLUInt, 8, 1};  // bool as uint8, as NumPy 1.24 exports it
  throw InputError("array",
                   "of dtype " + py::str(static_cast<py::object>(dtype)).cast<std::string>(),
                   "an array of floats, integers or bools");
}

// The capsule of one DLManagedTensor over the array's memory.
py::capsule dlpack_capsule(const py::array& array) {
  auto* e = new Exported;
  e->array = array.ptr();
  Py_INCREF(e->array);
  const int ndim = static_cast<int>(array.ndim());
  const auto item = static_cast<std::int64_t>(array.itemsize());
  for (int d = 0; d < ndim; ++d) {
    e->shape.push_back(array.shape(d));
    e->strides.push_back(array.strides(d) / item);  // DLPack counts strides in elements
  }
  DLTensor& t = e->tensor.dl_tensor;
  t.data = const_cast<void*>(array.data());
  t.device = {kDLCPU, 0};
  t.ndim = ndim;
  t.dtype = dl_type_of(array.dtype());
  t.shape = e->shape.data();
  t.strides = e->strides.data();
  t.byte_offset = 0;
  e->tensor.manager_ctx = e;
  e->tensor.deleter = delete_exported;
  // A capsule nobody consumed deletes its tensor; a consumer renames it and calls the deleter
  // itself when it is done.
  PyObject* capsule = PyCapsule_New(&e->tensor, kCapsuleName, [](PyObject* self) {
    if (!PyCapsule_IsValid(self, kCapsuleName)) return;  // consumed ("used_dltensor")
    auto* tensor = static_cast<DLManagedTensor*>(PyCapsule_GetPointer(self, kCapsuleName));
    tensor->deleter(tensor);
  });
  if (capsule == nullptr) {
    delete_exported(&e->tensor);
    throw py::error_already_set();
  }
  return py::reinterpret_steal<py::capsule>(capsule);
}
#endif

// What jelly.dlpack returns: the array, handed to a DLPack consumer on request.
struct DLPackExport {
  py::array array;
};

}  // namespace

void bind_dlpack(py::module_& m) {
  py::class_<DLPackExport>(m, "DLPackExport",
                           "An array offered to DLPack consumers without a copy "
                           "(jelly.dlpack(array)): torch.from_dlpack(it), numpy.from_dlpack(it).")
      .def(
          "__dlpack__",
          [](const DLPackExport& e, const py::object& stream) -> py::object {
            if (!stream.is_none()) {
              throw InputError("stream", py::str(stream).cast<std::string>(),
                               "None (the memory is on the CPU)");
            }
#ifdef JELLY_HAVE_DLPACK
            return dlpack_capsule(e.array);
#else
            (void)e;
            throw InputError(
                "jelly was built without DLPack (its header dlpack/dlpack.h, Debian's "
                "libdlpack-dev, was not found); numpy.array(a) copies instead");
#endif
          },
          py::kw_only(), py::arg("stream") = py::none(),
          "A DLPack capsule of the array's memory (CPU; the tensor keeps the array alive).")
      .def(
          "__dlpack_device__", [](const DLPackExport&) { return py::make_tuple(1, 0); },
          "(1, 0): kDLCPU, device 0.")
      .def_property_readonly(
          "array", [](const DLPackExport& e) { return e.array; }, "The array offered.")
      .def("__repr__", [](const DLPackExport& e) {
        return "<jelly.DLPackExport of " + py::repr(e.array).cast<std::string>() + ">";
      });
  m.def(
      "dlpack", [](const py::array& array) { return DLPackExport{array}; }, py::arg("array"),
      "The array (e.g. sim.state.x, a read-only view, which NumPy 1.24 does not export) as an "
      "object that DLPack consumers take without a copy: torch.from_dlpack(jelly.dlpack(x)). "
      "DLPack has no read-only flag: a consumer that writes into the tensor writes into the "
      "simulator's state (between steps that is an edit like state.x = ...; during another "
      "thread's step it is a race).");
}

}  // namespace jelly::python
