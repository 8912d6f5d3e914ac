#include <jelly/solvers/integrators/xpbd_options.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

namespace jelly {

const std::vector<EnumName<XpbdSweep>>& xpbd_sweeps() {
  static const std::vector<EnumName<XpbdSweep>> table{
      {XpbdSweep::kJacobi, "jacobi",
       "every spring from the same positions (symmetric, conserves momentum)"},
      {XpbdSweep::kGaussSeidel, "gauss_seidel",
       "one spring after the other in the model's order (breaks symmetry)"},
  };
  return table;
}

void XpbdOptions::validate(const std::string& prefix) const {
  require(substeps >= 1 && substeps <= 100000, prefix + "substeps", substeps,
          "an integer in [1, 100000]");
  require(iterations >= 1 && iterations <= 10000, prefix + "iterations", iterations,
          "an integer in [1, 10000]");
  require(name_of(xpbd_sweeps(), sweep) != "unknown", prefix + "sweep", static_cast<int>(sweep),
          "one of " + quoted_names(xpbd_sweeps()));
  require(name_of(position_contact_modes(), contact) != "unknown", prefix + "contact",
          static_cast<int>(contact), "one of " + quoted_names(position_contact_modes()));
}

}  // namespace jelly

namespace jelly {

XpbdOptions XpbdOptions::read(JsonFields& f) {
  XpbdOptions o;
  o.substeps = f.integer_or("substeps", o.substeps);
  o.iterations = f.integer_or("iterations", o.iterations);
  o.sweep =
      value_of(xpbd_sweeps(), f.string_or("sweep", std::string(name_of(xpbd_sweeps(), o.sweep))),
               f.path("sweep"));
  o.contact =
      value_of(position_contact_modes(),
               f.string_or("contact", std::string(name_of(position_contact_modes(), o.contact))),
               f.path("contact"));
  o.validate(f.prefix());
  return o;
}

Json XpbdOptions::to_json() const {
  Json out = Json::object();
  out["substeps"] = substeps;
  out["iterations"] = iterations;
  out["sweep"] = std::string(name_of(xpbd_sweeps(), sweep));
  out["contact"] = std::string(name_of(position_contact_modes(), contact));
  return out;
}

}  // namespace jelly
