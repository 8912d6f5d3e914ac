#pragma once
// Python properties from a field table (core/detail/field_table.hpp): one property per field,
// typed as the table says (int, float, bool, str), documented with its help, what is allowed,
// its default and unit. A write converts the value as a scene's JSON would be read (a choice's
// unknown name raises InputError naming the field's scene path); ranges are checked by
// validate() and when the options are used, as a scene's are. The class attribute `_fields`
// lists (name, stub annotation) for the stub check (tests/python/test_module.py); vec3 fields
// are NumPy arrays (_FloatArray), object and list rows are bound by hand.
#include <limits>
#include <string>

#include <jelly/core/detail/field_table.hpp>
#include <jelly/core/detail/json.hpp>

#include "common.hpp"

namespace jelly::python {

inline const char* python_type_of(FieldType type) {
  switch (type) {
    case FieldType::kInteger:
      return "int";
    case FieldType::kNumber:
      return "float";
    case FieldType::kBoolean:
      return "bool";
    case FieldType::kString:
    case FieldType::kChoice:
    case FieldType::kFile:
      return "str";
    case FieldType::kVec3:
      return "list";
    case FieldType::kObject:
    case FieldType::kList:
      return "object";
  }
  return "object";
}

// A field's annotation in the .pyi stub (what _fields lists): vec3 fields are NumPy arrays.
inline const char* stub_type_of(FieldType type) {
  return type == FieldType::kVec3 ? "_FloatArray" : python_type_of(type);
}

template <typename S>
std::string field_docstring(const Field<S>& f) {
  const S defaults{};
  std::string doc = std::string(f.help) + ". Allowed: " + f.allowed;
  if (!f.unit.empty()) doc += "; unit: " + std::string(f.unit);
  Json out = Json::object();
  f.write(defaults, out, f.name);
  return doc + "; default " + out[std::string(f.name)].dump() + ".";
}

// Defines the table's fields as properties of `cls` (the table must outlive the module: the
// tables are function-local statics). Messages name `path`.<field> (default: the table's scene
// path).
template <typename S, typename... Extra>
void def_fields(py::class_<S, Extra...>& cls, const FieldTable<S>& table, const char* path = "") {
  py::list names;
  const std::string prefix = *path ? std::string(path) : std::string(table.path);
  for (const Field<S>& field : table.fields) {
    // Object and list rows (a path, a list of pins) are bound by hand, as their own code reads
    // them.
    if (field.type == FieldType::kObject || field.type == FieldType::kList) continue;
    const Field<S>* f = &field;
    const auto get = [f](const S& s) -> py::object {
      Json out = Json::object();
      f->write(s, out, f->name);
      const Json& v = out[std::string(f->name)];
      if (v.is_null()) return py::none();  // an optional member without a value
      switch (f->type) {
        case FieldType::kInteger:
          return py::int_(v.get<long long>());
        case FieldType::kNumber:
          // "inf": a number_or_inf field's infinity.
          return py::float_(v.is_string() ? std::numeric_limits<double>::infinity()
                                          : v.get<double>());
        case FieldType::kBoolean:
          return py::bool_(v.get<bool>());
        case FieldType::kVec3: {
          const std::vector<double> c = v.get<std::vector<double>>();
          return py::cast(Vec3(c[0], c[1], c[2]));  // a NumPy array, as Eigen members are
        }
        default:
          return py::str(v.get<std::string>());
      }
    };
    const auto set = [f, prefix](S& s, const py::object& value) {
      const std::string field_path = json_child(prefix, f->name);
      Json v;
      try {
        switch (f->type) {
          case FieldType::kInteger:
            if (py::isinstance<py::bool_>(value)) throw py::cast_error();
            v = value.cast<long long>();
            break;
          case FieldType::kNumber:
            if (py::isinstance<py::bool_>(value)) throw py::cast_error();
            v = value.cast<double>();
            break;
          case FieldType::kBoolean:
            if (!py::isinstance<py::bool_>(value)) throw py::cast_error();
            v = value.cast<bool>();
            break;
          case FieldType::kVec3:
            v = value.cast<std::vector<double>>();
            break;
          default:
            if (!py::isinstance<py::str>(value)) throw py::cast_error();
            v = value.cast<std::string>();
            break;
        }
      } catch (const py::cast_error&) {
        throw InputError(field_path, py::repr(value).cast<std::string>(),
                         std::string("a Python ") + python_type_of(f->type) + ": " + f->allowed);
      }
      Json object = Json::object();
      object[std::string(f->name)] = v;
      JsonFields fields(object, prefix);
      f->read(fields, s, f->name);
    };
    cls.def_property(std::string(field.name).c_str(), get, set, field_docstring(field).c_str());
    names.append(py::make_tuple(std::string(field.name), stub_type_of(field.type)));
  }
  cls.attr("_fields") = py::tuple(names);
}

}  // namespace jelly::python
