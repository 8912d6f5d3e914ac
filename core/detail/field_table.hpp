#pragma once
// Field tables: each field of an options or spec struct declared once (name, member, type,
// default, unit, constraint, one-line help), from which its JSON reading and writing, its
// validation messages, its Python properties and the scene-key reference all come (as Drake's
// Serialize() names each field once). A table is declared in the .cpp of its struct with the
// factories below; generic code reads tables through FieldTable and FieldDoc.
//
// Only core/json_fwd.hpp here: the factories' bodies call the json_field_* helpers, declared
// below and defined in core/json.cpp, so that a header including this one stays free of
// nlohmann's definitions.
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

enum class FieldType {
  kInteger,
  kNumber,
  kBoolean,
  kString,
  kChoice,
  kVec3,
  kObject,
  kList,
  kFile
};
// "integer", "number", "boolean", "string", "choice", "vec3", "object", "list", "file" (a
// file name, relative to the scene file's folder). An object or
// list field is one a table row cannot read generically (a polymorphic value, a list of
// kinds): its own code reads and writes it, the table names it in order, documents it and
// gives an example.
std::string_view field_type_name(FieldType type);

// A numeric field's allowed interval; numbers must also be finite unless `finite` is false
// (an infinite limit that means "not checked"; never NaN). `or_zero`: 0 is allowed besides the
// interval (an "off" value).
struct FieldRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;
  bool or_zero = false;
  bool finite = true;

  bool contains(double v) const {
    if (std::isnan(v) || (finite && !std::isfinite(v))) return false;
    if (or_zero && v == 0) return true;
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  bool bounded() const { return std::isfinite(lo) || std::isfinite(hi); }
};
// Intervals by their notation: range_closed(1, 100) = [1, 100], range_open(0, 1) = (0, 1), ...
inline FieldRange range_closed(double lo, double hi) { return {lo, hi, false, false, false}; }
inline FieldRange range_open(double lo, double hi) { return {lo, hi, true, true, false}; }
inline FieldRange range_closed_open(double lo, double hi) { return {lo, hi, false, true, false}; }
inline FieldRange range_open_closed(double lo, double hi) { return {lo, hi, true, false, false}; }
inline FieldRange range_at_least(double lo) {
  return {lo, std::numeric_limits<double>::infinity(), false, false, false};
}
inline FieldRange range_above(double lo) {
  return {lo, std::numeric_limits<double>::infinity(), true, false, false};
}
inline FieldRange range_finite() { return {}; }
inline FieldRange range_or_zero(FieldRange r) {
  r.or_zero = true;
  return r;
}
inline FieldRange range_or_infinite(FieldRange r) {
  r.finite = false;
  return r;
}

// One field of struct S. Built by the factories below; the function pointers know the member.
template <typename S>
struct Field {
  std::string_view name;
  FieldType type;
  std::string_view unit;  // "" = none
  std::string_view help;  // one line
  // What a message says is allowed ("an integer in [1, 100]"); for choices "one of ...".
  std::string allowed;
  FieldRange range;          // numbers and integers; a vec3's length (finite components)
  bool constrained = false;  // whether some value of its type is refused
  // Reads key `name` of `fields` into the member when present (marking it known); converts,
  // and for a choice refuses an unknown name, with an InputError naming the field's JSON path.
  void (*read)(JsonFields& fields, S& s, std::string_view name) = nullptr;
  // Sets out[name] to the member's value.
  void (*write)(const S& s, Json& out, std::string_view name) = nullptr;
  bool (*valid)(const S& s, const FieldRange& range) = nullptr;
  // The value as messages and the reference show it (JSON text: 10, 1e-08, "metis").
  std::string (*text)(const S& s) = nullptr;
  std::vector<std::string> (*choices)() = nullptr;  // a choice's names; nullptr for other types
  // A scene must give it ("<path> is missing: it is required").
  bool required = false;
  // Whether the member holds what a default-constructed S holds (nullptr: object fields).
  bool (*is_default)(const S& s) = nullptr;
  // Written only when not the default (an optional member: only when it holds a value).
  bool omit_default = false;
  // An object or list field's example value (JSON text) for the reference and the tests.
  std::string_view example{};
  // A vec3 whose `range` bounds each component (a colour, a box's size), not its length.
  bool per_component = false;
  // Where a scene holds the field when the struct is not one scene object (SimulatorOptions'
  // dt is "integrator.dt"); messages name it instead of prefix + name.
  std::string_view scene_key{};
};

// The fields of one struct, in the order a scene lists them, and the rules between fields.
template <typename S>
struct FieldTable {
  std::string_view name;   // the C++ (and Python) type: "ImplicitEulerOptions"
  std::string_view path;   // where a scene holds it: "integrator.options"
  std::string_view title;  // what it is, one line
  std::vector<Field<S>> fields;
  // Rules between fields, after each field's own: throws InputError naming prefix + field.
  void (*check)(const S& s, const std::string& prefix) = nullptr;
  // Defaults that depend on other fields, after the fields are read and before validation
  // (json_field_has says whether a key was given).
  void (*after_read)(JsonFields& fields, S& s) = nullptr;
};

// A field as the reference and other generic readers see it, without its struct.
struct FieldDoc {
  std::string name, type, unit, help, allowed, default_text;
  FieldRange range;
  bool constrained = false;
  bool required = false;
  bool optional = false;  // a default of null: none unless given
  bool per_component = false;
  std::string example;  // object and list fields: a JSON example
  std::vector<std::string> choices;
};
struct FieldTableDoc {
  std::string name, path, title;
  // The integrators that read it (integrator.options), or the kind it is (terrains[i],
  // bodies[i]); empty for the other paths.
  std::vector<std::string> used_by;
  std::vector<FieldDoc> fields;
};

// The documents of the field tables an optional component brings (arkode's options), added by
// its register_<name>_component(); the reference lists them after the core's. Defined in
// core/json.cpp.
using FieldTableDocument = FieldTableDoc (*)();
std::vector<FieldTableDocument>& component_field_documents();

// The helpers the factories call (defined in core/json.cpp).
int json_field_integer(JsonFields& f, std::string_view key, int fallback);
long long json_field_long(JsonFields& f, std::string_view key, long long fallback);
Real json_field_number(JsonFields& f, std::string_view key, Real fallback);
bool json_field_boolean(JsonFields& f, std::string_view key, bool fallback);
std::string json_field_string(JsonFields& f, std::string_view key, const std::string& fallback);
Vec3 json_field_vec3(JsonFields& f, std::string_view key, const Vec3& fallback);
// A number, or the string "inf" for +infinity (message: "a number or \"inf\"").
Real json_field_number_or_inf(JsonFields& f, std::string_view key, Real fallback);
// A required file name resolved against the object's base directory (JsonFields::file).
std::string json_field_file(JsonFields& f, std::string_view key);
// Throws "<path> is missing: it is required" unless the object has `key` (marking it known).
void json_field_require(JsonFields& f, std::string_view key);
std::string json_field_path(const JsonFields& f, std::string_view key);
// The value under `key` (marking it known), or nullptr.
const Json* json_field_value(JsonFields& f, std::string_view key);
void json_field_put_json(Json& out, std::string_view key, const Json& value);
bool json_field_has(const JsonFields& f, std::string_view key);
void json_field_reject_unknown(const JsonFields& f);
void json_field_put(Json& out, std::string_view key, long long value);
void json_field_put(Json& out, std::string_view key, Real value);
void json_field_put(Json& out, std::string_view key, bool value);
void json_field_put(Json& out, std::string_view key, const std::string& value);
void json_field_put(Json& out, std::string_view key, const Vec3& value);
// A number, or "inf" for +infinity.
void json_field_put_or_inf(Json& out, std::string_view key, Real value);
std::string json_field_text(long long value);
std::string json_field_text(Real value);
std::string json_field_text(bool value);
std::string json_field_text(const std::string& value);
std::string json_field_text(const Vec3& value);
// An optional member with no value, as messages and the reference show it.
inline std::string json_field_none() { return "none"; }
// The JSON text of the value `write` puts under `key` in an empty object (the reference's
// defaults: shortest round-trip numbers).
std::string json_field_dump(const std::function<void(Json&)>& write, std::string_view key);

namespace field_detail {

template <typename M>
struct MemberOf;
template <typename S, typename T>
struct MemberOf<T S::*> {
  using Struct = S;
  using Value = T;
};

// One step of a member path: a data member (`&S::m`) or an array element (an index).
template <auto M, typename T>
auto& step(T& t) {
  if constexpr (std::is_member_object_pointer_v<decltype(M)>) {
    return t.*M;
  } else {
    return t[M];
  }
}
// The member a path names: access<&Body::pose, &Pose::position>(body) = body.pose.position;
// access<&Box::n, 0>(box) = box.n[0].
template <auto M, auto... Rest, typename T>
auto& access(T& t) {
  if constexpr (sizeof...(Rest) == 0) {
    return step<M>(t);
  } else {
    return access<Rest...>(step<M>(t));
  }
}

template <auto M, auto...>
struct First {
  using Struct = typename MemberOf<decltype(M)>::Struct;
};
// The struct a member path starts from, and the type it ends at.
template <auto... Ms>
using StructOf = typename First<Ms...>::Struct;
template <auto... Ms>
using ValueOf = std::remove_reference_t<decltype(access<Ms...>(std::declval<StructOf<Ms...>&>()))>;

// Whether the member holds what a default-constructed struct holds.
template <auto... Ms>
bool is_default(const StructOf<Ms...>& s) {
  static const StructOf<Ms...> defaults{};
  return access<Ms...>(s) == access<Ms...>(defaults);
}

}  // namespace field_detail

// An integer member (int or long): JSON integers, `range` in the message's words `allowed`.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> integer_field(std::string_view name, std::string_view unit,
                                                   FieldRange range, std::string allowed,
                                                   std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  using T = field_detail::ValueOf<Ms...>;
  static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>);
  Field<S> f{name, FieldType::kInteger, unit, help, std::move(allowed), range, range.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    if constexpr (sizeof(T) <= sizeof(int)) {
      field_detail::access<Ms...>(s) = json_field_integer(j, key, field_detail::access<Ms...>(s));
    } else {
      field_detail::access<Ms...>(s) =
          static_cast<T>(json_field_long(j, key, field_detail::access<Ms...>(s)));
    }
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, static_cast<long long>(field_detail::access<Ms...>(s)));
  };
  f.valid = [](const S& s, const FieldRange& r) {
    return r.contains(static_cast<double>(field_detail::access<Ms...>(s)));
  };
  f.text = [](const S& s) {
    return json_field_text(static_cast<long long>(field_detail::access<Ms...>(s)));
  };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A floating-point member: finite, in `range`.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> number_field(std::string_view name, std::string_view unit,
                                                  FieldRange range, std::string allowed,
                                                  std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  static_assert(std::is_floating_point_v<field_detail::ValueOf<Ms...>>);
  Field<S> f{name, FieldType::kNumber, unit, help, std::move(allowed), range, range.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    field_detail::access<Ms...>(s) = json_field_number(j, key, field_detail::access<Ms...>(s));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, field_detail::access<Ms...>(s));
  };
  f.valid = [](const S& s, const FieldRange& r) {
    return r.contains(field_detail::access<Ms...>(s));
  };
  f.text = [](const S& s) {
    return json_field_text(static_cast<Real>(field_detail::access<Ms...>(s)));
  };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A bool member: true or false.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> boolean_field(std::string_view name, std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  static_assert(std::is_same_v<field_detail::ValueOf<Ms...>, bool>);
  Field<S> f{name, FieldType::kBoolean, "", help, "true or false", FieldRange{}, false};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    field_detail::access<Ms...>(s) = json_field_boolean(j, key, field_detail::access<Ms...>(s));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, field_detail::access<Ms...>(s));
  };
  f.valid = [](const S&, const FieldRange&) { return true; };
  f.text = [](const S& s) { return json_field_text(field_detail::access<Ms...>(s)); };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A free std::string member (checked elsewhere, if at all).
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> string_field(std::string_view name, std::string allowed,
                                                  std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  static_assert(std::is_same_v<field_detail::ValueOf<Ms...>, std::string>);
  Field<S> f{name, FieldType::kString, "", help, std::move(allowed), FieldRange{}, false};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    field_detail::access<Ms...>(s) = json_field_string(j, key, field_detail::access<Ms...>(s));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, field_detail::access<Ms...>(s));
  };
  f.valid = [](const S&, const FieldRange&) { return true; };
  f.text = [](const S& s) { return json_field_text(field_detail::access<Ms...>(s)); };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A Vec3 member, a JSON array [x, y, z] of finite numbers whose length is in `length` (any:
// range_finite()).
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> vec3_field(std::string_view name, std::string_view unit,
                                                FieldRange length, std::string allowed,
                                                std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  static_assert(std::is_same_v<field_detail::ValueOf<Ms...>, Vec3>);
  Field<S> f{name, FieldType::kVec3, unit, help, std::move(allowed), length, length.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    field_detail::access<Ms...>(s) = json_field_vec3(j, key, field_detail::access<Ms...>(s));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, field_detail::access<Ms...>(s));
  };
  f.valid = [](const S& s, const FieldRange& r) {
    // stableNorm: the length of [1e308, 0, 0] is finite (norm() would overflow).
    return field_detail::access<Ms...>(s).allFinite() &&
           r.contains(field_detail::access<Ms...>(s).stableNorm());
  };
  f.text = [](const S& s) { return json_field_text(field_detail::access<Ms...>(s)); };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A floating-point member that may be +infinity, given as the string "inf" (an elevator's
// mass, a force's end time): `range` should allow it (range_or_infinite).
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> number_or_inf_field(std::string_view name,
                                                         std::string_view unit, FieldRange range,
                                                         std::string allowed,
                                                         std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  static_assert(std::is_floating_point_v<field_detail::ValueOf<Ms...>>);
  Field<S> f{name, FieldType::kNumber, unit, help, std::move(allowed), range, range.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    field_detail::access<Ms...>(s) =
        json_field_number_or_inf(j, key, field_detail::access<Ms...>(s));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put_or_inf(out, key, field_detail::access<Ms...>(s));
  };
  f.valid = [](const S& s, const FieldRange& r) {
    return r.contains(field_detail::access<Ms...>(s));
  };
  f.text = [](const S& s) {
    return json_field_text(static_cast<Real>(field_detail::access<Ms...>(s)));
  };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A std::optional<Real> member: none unless the key is given; then finite, in `range`.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> optional_number_field(std::string_view name,
                                                           std::string_view unit, FieldRange range,
                                                           std::string allowed,
                                                           std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  Field<S> f{name, FieldType::kNumber, unit, help, std::move(allowed), range, range.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    auto& m = field_detail::access<Ms...>(s);
    if (json_field_has(j, key)) {
      m = json_field_number(j, key, 0);
    } else {
      json_field_number(j, key, 0);  // known, absent
    }
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    const auto& m = field_detail::access<Ms...>(s);
    if (m) json_field_put(out, key, static_cast<Real>(*m));
  };
  f.valid = [](const S& s, const FieldRange& r) {
    const auto& m = field_detail::access<Ms...>(s);
    return !m || r.contains(*m);
  };
  f.text = [](const S& s) {
    const auto& m = field_detail::access<Ms...>(s);
    return m ? json_field_text(static_cast<Real>(*m)) : json_field_none();
  };
  f.omit_default = true;
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A std::optional<Vec3> member: none unless the key is given; then finite components each in
// `component` (a colour's [0, 1]).
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> optional_vec3_field(std::string_view name,
                                                         std::string_view unit,
                                                         FieldRange component, std::string allowed,
                                                         std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  Field<S> f{name,      FieldType::kVec3,   unit, help, std::move(allowed),
             component, component.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    auto& m = field_detail::access<Ms...>(s);
    if (json_field_has(j, key)) {
      m = json_field_vec3(j, key, Vec3::Zero());
    } else {
      json_field_vec3(j, key, Vec3::Zero());  // known, absent
    }
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    const auto& m = field_detail::access<Ms...>(s);
    if (m) json_field_put(out, key, Vec3(*m));
  };
  f.valid = [](const S& s, const FieldRange& r) {
    const auto& m = field_detail::access<Ms...>(s);
    if (!m) return true;
    for (int k = 0; k < 3; ++k)
      if (!r.contains((*m)[k])) return false;
    return true;
  };
  f.text = [](const S& s) {
    const auto& m = field_detail::access<Ms...>(s);
    return m ? json_field_text(Vec3(*m)) : json_field_none();
  };
  f.omit_default = true;
  f.per_component = true;
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A Vec3 member whose components are each finite and in `component` (three sizes > 0).
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> vec3_each_field(std::string_view name, std::string_view unit,
                                                     FieldRange component, std::string allowed,
                                                     std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  Field<S> f = vec3_field<Ms...>(name, unit, component, std::move(allowed), help);
  f.per_component = true;
  f.valid = [](const S& s, const FieldRange& r) {
    const Vec3& m = field_detail::access<Ms...>(s);
    for (int k = 0; k < 3; ++k)
      if (!r.contains(m[k])) return false;
    return true;
  };
  return f;
}

// A required file name (a mesh), resolved against the scene file's folder when relative and
// held as an absolute path; never empty.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> file_field(std::string_view name, std::string allowed,
                                                std::string_view help) {
  using S = field_detail::StructOf<Ms...>;
  static_assert(std::is_same_v<field_detail::ValueOf<Ms...>, std::string>);
  Field<S> f{name, FieldType::kFile, "", help, std::move(allowed), FieldRange{}, true};
  f.required = true;
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    field_detail::access<Ms...>(s) = json_field_file(j, key);
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, field_detail::access<Ms...>(s));
  };
  f.valid = [](const S& s, const FieldRange&) { return !field_detail::access<Ms...>(s).empty(); };
  f.text = [](const S& s) { return json_field_text(field_detail::access<Ms...>(s)); };
  f.is_default = &field_detail::is_default<Ms...>;
  return f;
}

// A field its own code reads and writes (`type` kObject or kList): a polymorphic value (a
// path, an elevator's motion) or a list of kinds (bodies, terrains, pins). `read` and `write`
// have Field's signatures; the row gives it its place in the order, its documentation and an
// example. Validation is the reader's.
template <typename S>
Field<S> object_field(std::string_view name, FieldType type, std::string allowed,
                      std::string_view help, std::string_view example,
                      void (*read)(JsonFields&, S&, std::string_view),
                      void (*write)(const S&, Json&, std::string_view)) {
  Field<S> f{name, type, "", help, std::move(allowed), FieldRange{}, false};
  f.read = read;
  f.write = write;
  f.valid = [](const S&, const FieldRange&) { return true; };
  f.text = [](const S&) { return std::string("{...}"); };
  f.example = example;
  return f;
}

// A member whose type has `static T read(const Json&, const std::string& path)` and
// `Json to_json() const` (Path, ElevatorMotion): an object field.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> json_value_field(std::string_view name, std::string allowed,
                                                      std::string_view help,
                                                      std::string_view example) {
  using S = field_detail::StructOf<Ms...>;
  using T = field_detail::ValueOf<Ms...>;
  return object_field<S>(
      name, FieldType::kObject, std::move(allowed), help, example,
      [](JsonFields& j, S& s, std::string_view key) {
        if (const Json* v = json_field_value(j, key))
          field_detail::access<Ms...>(s) = T::read(*v, json_field_path(j, key));
      },
      [](const S& s, Json& out, std::string_view key) {
        json_field_put_json(out, key, field_detail::access<Ms...>(s).to_json());
      });
}

// Modifiers of a row: the key is required; the key is written only when its value is not the
// default (a body's velocity); the row checks `valid` instead of its type's own check.
template <typename S>
Field<S> required(Field<S> f) {
  f.required = true;
  return f;
}
template <typename S>
Field<S> omit_default(Field<S> f) {
  f.omit_default = true;
  return f;
}

// An enum member named by the table `Names` (core/errors.hpp): "one of ...".
template <auto M, auto Names>
Field<field_detail::StructOf<M>> choice_field(std::string_view name, std::string_view help) {
  using S = field_detail::StructOf<M>;
  Field<S> f{name, FieldType::kChoice, "", help, "one of " + quoted_names(Names()), FieldRange{},
             true};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    const std::string chosen =
        json_field_string(j, key, std::string(name_of(Names(), field_detail::access<M>(s))));
    field_detail::access<M>(s) = value_of(Names(), chosen, json_field_path(j, key));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, std::string(name_of(Names(), field_detail::access<M>(s))));
  };
  f.valid = [](const S& s, const FieldRange&) {
    return name_of(Names(), field_detail::access<M>(s)) != "unknown";
  };
  // An unknown value shows as its number (as the messages did before the tables).
  f.text = [](const S& s) {
    const std::string_view n = name_of(Names(), field_detail::access<M>(s));
    return n != "unknown" ? json_field_text(std::string(n))
                          : json_field_text(static_cast<long long>(field_detail::access<M>(s)));
  };
  f.choices = [] {
    std::vector<std::string> out;
    for (const auto& e : Names()) out.emplace_back(e.name);
    return out;
  };
  f.is_default = &field_detail::is_default<M>;
  return f;
}

// Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
// field, then the table's rules between fields.
template <typename S>
void validate_fields(const FieldTable<S>& table, const S& s, const std::string& prefix) {
  for (const Field<S>& f : table.fields) {
    if (!f.valid(s, f.range)) {
      throw InputError(
          f.scene_key.empty() ? prefix + std::string(f.name) : std::string(f.scene_key), f.text(s),
          f.allowed);
    }
  }
  if (table.check) table.check(s, prefix);
}

// Reads the table's keys of `fields` into `s` (missing keys keep their values), refuses any
// other key when `reject_unknown` (else the caller reads more keys of the object), then
// validates with the fields' JSON paths.
template <typename S>
void read_fields(const FieldTable<S>& table, JsonFields& fields, S& s, const std::string& prefix,
                 bool reject_unknown = false) {
  for (const Field<S>& f : table.fields) {
    if (f.required) json_field_require(fields, f.name);
    f.read(fields, s, f.name);
  }
  if (table.after_read) table.after_read(fields, s);
  if (reject_unknown) json_field_reject_unknown(fields);
  validate_fields(table, s, prefix);
}

// Sets out[name] for every field, in the table's order (`out` a JSON object).
template <typename S>
void write_fields(const FieldTable<S>& table, const S& s, Json& out) {
  for (const Field<S>& f : table.fields) {
    if (f.omit_default && f.is_default && f.is_default(s)) continue;
    f.write(s, out, f.name);
  }
}

// The table as the reference shows it, with the defaults of a default-constructed S.
template <typename S>
FieldTableDoc document_fields(const FieldTable<S>& table, std::vector<std::string> used_by = {}) {
  FieldTableDoc doc{std::string(table.name),
                    std::string(table.path),
                    std::string(table.title),
                    std::move(used_by),
                    {}};
  const S defaults{};
  for (const Field<S>& f : table.fields) {
    FieldDoc d;
    d.name = f.name;
    d.type = field_type_name(f.type);
    d.unit = f.unit;
    d.help = f.help;
    d.allowed = f.allowed;
    // An object or list row's default is its own code's (the reference shows an example).
    const bool object = f.type == FieldType::kObject || f.type == FieldType::kList;
    d.default_text =
        object ? std::string("null")
               : json_field_dump([&](Json& out) { f.write(defaults, out, f.name); }, f.name);
    d.range = f.range;
    d.constrained = f.constrained;
    d.required = f.required;
    d.example = f.example;
    d.optional = !object && d.default_text == "null";
    d.per_component = f.per_component;
    if (f.choices) d.choices = f.choices();
    doc.fields.push_back(std::move(d));
  }
  return doc;
}

}  // namespace jelly
