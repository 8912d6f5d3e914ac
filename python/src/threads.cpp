// Threads: one lock per Simulator object serialises every call that reads or changes it, so that
// a simulator used from several Python threads never runs two calls at once (issue 38). The GIL
// is released before waiting for the lock, and the lock is taken before the GIL, never the other
// way round: a thread that holds the lock and calls back into Python (a callback, an observer)
// can always take the GIL. Different simulators have different locks and run in parallel.
#include <mutex>
#include <string>

#include <jelly/solvers/simulator.hpp>

#include "common.hpp"

namespace jelly::python {

namespace {

// The attribute of a Simulator object (which has a __dict__) that holds its lock.
constexpr const char* kLockAttribute = "_jelly_lock";

std::recursive_mutex& lock_of(py::handle simulator, py::object& holder) {
  if (!py::isinstance<Simulator>(simulator)) {
    throw py::type_error("expected a jelly.Simulator, not " +
                         std::string(py::str(py::type::of(simulator).attr("__name__"))));
  }
  holder = py::getattr(simulator, kLockAttribute, py::none());
  if (holder.is_none()) {  // made under the GIL: no other thread makes it at the same time
    holder = py::capsule(new std::recursive_mutex,
                         [](void* p) { delete static_cast<std::recursive_mutex*>(p); });
    py::setattr(simulator, kLockAttribute, holder);
  }
  return *static_cast<std::recursive_mutex*>(holder.cast<py::capsule>());
}

// A method of Simulator (the function an instancemethod wraps) called under the lock.
py::cpp_function serialised_method(py::handle cls, const std::string& name, py::object method,
                                   const std::string& doc) {
  return py::cpp_function(
      [method](py::handle self, py::args args, py::kwargs kwargs) -> py::object {
        SimulatorLock lock(self);
        return method(self, *args, **kwargs);
      },
      py::name(name.c_str()), py::is_method(cls), py::doc(doc.c_str()));
}

// A property's getter or setter called under the lock.
py::object serialised_accessor(py::object accessor, const std::string& doc) {
  if (accessor.is_none()) return accessor;
  return py::cpp_function(
      [accessor](py::handle self, py::args args) -> py::object {
        SimulatorLock lock(self);
        return accessor(self, *args);
      },
      py::doc(doc.c_str()));
}

}  // namespace

SimulatorLock::SimulatorLock(py::handle simulator) : mutex_(&lock_of(simulator, holder_)) {
  if (mutex_->try_lock()) return;  // free, or already held by this thread (a callback)
  py::gil_scoped_release release;  // the thread that holds it may need the GIL to finish
  mutex_->lock();
}

SimulatorLock::~SimulatorLock() { mutex_->unlock(); }

void serialise_simulator(py::module_& m) {
  py::object cls = m.attr("Simulator");
  const py::object property = py::module_::import("builtins").attr("property");
  // The docstrings are the original functions' own, signatures included.
  py::options options;
  options.disable_function_signatures();
  const py::dict members(cls.attr("__dict__"));
  for (const auto& item : members) {
    const std::string name = item.first.cast<std::string>();
    if (name.rfind("__", 0) == 0 && name != "__repr__") continue;  // __init__ and the like
    const py::object value = py::reinterpret_borrow<py::object>(item.second);
    const std::string doc = py::str(value.attr("__doc__")).cast<std::string>();
    if (py::isinstance(value, property)) {
      py::setattr(cls, name.c_str(),
                  property(serialised_accessor(value.attr("fget"), doc),
                           serialised_accessor(value.attr("fset"), doc), py::none(), doc));
    } else if (PyInstanceMethod_Check(value.ptr())) {
      py::object method =
          py::reinterpret_borrow<py::object>(PyInstanceMethod_GET_FUNCTION(value.ptr()));
      py::setattr(cls, name.c_str(), serialised_method(cls, name, method, doc));
    }
  }
  // Functions of the module that take a simulator first.
  for (const char* name : {"restore"}) {
    py::object function = m.attr(name);
    const std::string doc = py::str(function.attr("__doc__")).cast<std::string>();
    m.attr(name) = py::cpp_function(
        [function](py::handle simulator, py::args args, py::kwargs kwargs) -> py::object {
          SimulatorLock lock(simulator);
          return function(simulator, *args, **kwargs);
        },
        py::name(name), py::doc(doc.c_str()));
  }
}

}  // namespace jelly::python
