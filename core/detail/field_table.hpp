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

enum class FieldType { kInteger, kNumber, kBoolean, kString, kChoice, kVec3 };
// "integer", "number", "boolean", "string", "choice", "vec3".
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
std::string json_field_path(const JsonFields& f, std::string_view key);
bool json_field_has(const JsonFields& f, std::string_view key);
void json_field_reject_unknown(const JsonFields& f);
void json_field_put(Json& out, std::string_view key, long long value);
void json_field_put(Json& out, std::string_view key, Real value);
void json_field_put(Json& out, std::string_view key, bool value);
void json_field_put(Json& out, std::string_view key, const std::string& value);
void json_field_put(Json& out, std::string_view key, const Vec3& value);
std::string json_field_text(long long value);
std::string json_field_text(Real value);
std::string json_field_text(bool value);
std::string json_field_text(const std::string& value);
std::string json_field_text(const Vec3& value);
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
template <auto M>
using StructOf = typename MemberOf<decltype(M)>::Struct;
template <auto M>
using ValueOf = typename MemberOf<decltype(M)>::Value;

}  // namespace field_detail

// An integer member (int or long): JSON integers, `range` in the message's words `allowed`.
template <auto M>
Field<field_detail::StructOf<M>> integer_field(std::string_view name, std::string_view unit,
                                               FieldRange range, std::string allowed,
                                               std::string_view help) {
  using S = field_detail::StructOf<M>;
  using T = field_detail::ValueOf<M>;
  static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>);
  Field<S> f{name, FieldType::kInteger, unit, help, std::move(allowed), range, range.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    if constexpr (sizeof(T) <= sizeof(int)) {
      s.*M = json_field_integer(j, key, s.*M);
    } else {
      s.*M = static_cast<T>(json_field_long(j, key, s.*M));
    }
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, static_cast<long long>(s.*M));
  };
  f.valid = [](const S& s, const FieldRange& r) { return r.contains(static_cast<double>(s.*M)); };
  f.text = [](const S& s) { return json_field_text(static_cast<long long>(s.*M)); };
  return f;
}

// A floating-point member: finite, in `range`.
template <auto M>
Field<field_detail::StructOf<M>> number_field(std::string_view name, std::string_view unit,
                                              FieldRange range, std::string allowed,
                                              std::string_view help) {
  using S = field_detail::StructOf<M>;
  static_assert(std::is_floating_point_v<field_detail::ValueOf<M>>);
  Field<S> f{name, FieldType::kNumber, unit, help, std::move(allowed), range, range.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    s.*M = json_field_number(j, key, s.*M);
  };
  f.write = [](const S& s, Json& out, std::string_view key) { json_field_put(out, key, s.*M); };
  f.valid = [](const S& s, const FieldRange& r) { return r.contains(s.*M); };
  f.text = [](const S& s) { return json_field_text(static_cast<Real>(s.*M)); };
  return f;
}

// A bool member: true or false.
template <auto M>
Field<field_detail::StructOf<M>> boolean_field(std::string_view name, std::string_view help) {
  using S = field_detail::StructOf<M>;
  static_assert(std::is_same_v<field_detail::ValueOf<M>, bool>);
  Field<S> f{name, FieldType::kBoolean, "", help, "true or false", FieldRange{}, false};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    s.*M = json_field_boolean(j, key, s.*M);
  };
  f.write = [](const S& s, Json& out, std::string_view key) { json_field_put(out, key, s.*M); };
  f.valid = [](const S&, const FieldRange&) { return true; };
  f.text = [](const S& s) { return json_field_text(s.*M); };
  return f;
}

// A free std::string member (checked elsewhere, if at all).
template <auto M>
Field<field_detail::StructOf<M>> string_field(std::string_view name, std::string allowed,
                                              std::string_view help) {
  using S = field_detail::StructOf<M>;
  static_assert(std::is_same_v<field_detail::ValueOf<M>, std::string>);
  Field<S> f{name, FieldType::kString, "", help, std::move(allowed), FieldRange{}, false};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    s.*M = json_field_string(j, key, s.*M);
  };
  f.write = [](const S& s, Json& out, std::string_view key) { json_field_put(out, key, s.*M); };
  f.valid = [](const S&, const FieldRange&) { return true; };
  f.text = [](const S& s) { return json_field_text(s.*M); };
  return f;
}

// A Vec3 member, a JSON array [x, y, z] of finite numbers whose length is in `length` (any:
// range_finite()).
template <auto M>
Field<field_detail::StructOf<M>> vec3_field(std::string_view name, std::string_view unit,
                                            FieldRange length, std::string allowed,
                                            std::string_view help) {
  using S = field_detail::StructOf<M>;
  static_assert(std::is_same_v<field_detail::ValueOf<M>, Vec3>);
  Field<S> f{name, FieldType::kVec3, unit, help, std::move(allowed), length, length.bounded()};
  f.read = [](JsonFields& j, S& s, std::string_view key) { s.*M = json_field_vec3(j, key, s.*M); };
  f.write = [](const S& s, Json& out, std::string_view key) { json_field_put(out, key, s.*M); };
  f.valid = [](const S& s, const FieldRange& r) {
    // stableNorm: the length of [1e308, 0, 0] is finite (norm() would overflow).
    return (s.*M).allFinite() && r.contains((s.*M).stableNorm());
  };
  f.text = [](const S& s) { return json_field_text(s.*M); };
  return f;
}

// An enum member named by the table `Names` (core/errors.hpp): "one of ...".
template <auto M, auto Names>
Field<field_detail::StructOf<M>> choice_field(std::string_view name, std::string_view help) {
  using S = field_detail::StructOf<M>;
  Field<S> f{name, FieldType::kChoice, "", help, "one of " + quoted_names(Names()), FieldRange{},
             true};
  f.read = [](JsonFields& j, S& s, std::string_view key) {
    const std::string chosen = json_field_string(j, key, std::string(name_of(Names(), s.*M)));
    s.*M = value_of(Names(), chosen, json_field_path(j, key));
  };
  f.write = [](const S& s, Json& out, std::string_view key) {
    json_field_put(out, key, std::string(name_of(Names(), s.*M)));
  };
  f.valid = [](const S& s, const FieldRange&) { return name_of(Names(), s.*M) != "unknown"; };
  // An unknown value shows as its number (as the messages did before the tables).
  f.text = [](const S& s) {
    const std::string_view n = name_of(Names(), s.*M);
    return n != "unknown" ? json_field_text(std::string(n))
                          : json_field_text(static_cast<long long>(s.*M));
  };
  f.choices = [] {
    std::vector<std::string> out;
    for (const auto& e : Names()) out.emplace_back(e.name);
    return out;
  };
  return f;
}

// Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
// field, then the table's rules between fields.
template <typename S>
void validate_fields(const FieldTable<S>& table, const S& s, const std::string& prefix) {
  for (const Field<S>& f : table.fields) {
    if (!f.valid(s, f.range)) throw InputError(prefix + std::string(f.name), f.text(s), f.allowed);
  }
  if (table.check) table.check(s, prefix);
}

// Reads the table's keys of `fields` into `s` (missing keys keep their values), refuses any
// other key when `reject_unknown` (else the caller reads more keys of the object), then
// validates with the fields' JSON paths.
template <typename S>
void read_fields(const FieldTable<S>& table, JsonFields& fields, S& s, const std::string& prefix,
                 bool reject_unknown = false) {
  for (const Field<S>& f : table.fields) f.read(fields, s, f.name);
  if (table.after_read) table.after_read(fields, s);
  if (reject_unknown) json_field_reject_unknown(fields);
  validate_fields(table, s, prefix);
}

// Sets out[name] for every field, in the table's order (`out` a JSON object).
template <typename S>
void write_fields(const FieldTable<S>& table, const S& s, Json& out) {
  for (const Field<S>& f : table.fields) f.write(s, out, f.name);
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
    d.default_text = json_field_dump([&](Json& out) { f.write(defaults, out, f.name); }, f.name);
    d.range = f.range;
    d.constrained = f.constrained;
    if (f.choices) d.choices = f.choices();
    doc.fields.push_back(std::move(d));
  }
  return doc;
}

}  // namespace jelly
