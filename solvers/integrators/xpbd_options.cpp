#include <jelly/solvers/integrators/integrator_options.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>

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

const FieldTable<XpbdOptions>& xpbd_fields() {
  using O = XpbdOptions;
  static const FieldTable<O> table{
      "XpbdOptions",
      "integrator.options",
      "Options of xpbd (docs/realtime.md)",
      {
          integer_field<&O::substeps>("substeps", "", range_closed(1, 100000),
                                      "an integer in [1, 100000]", "Substeps per step"),
          integer_field<&O::iterations>("iterations", "", range_closed(1, 10000),
                                        "an integer in [1, 10000]",
                                        "Sweeps over the springs and contacts per substep"),
          choice_field<&O::sweep, &xpbd_sweeps>("sweep", "How a sweep visits the springs"),
          choice_field<&O::contact, &position_contact_modes>("contact",
                                                             "How coulomb terrains enter the step"),
      },
  };
  return table;
}

void XpbdOptions::validate(const std::string& prefix) const {
  validate_fields(xpbd_fields(), *this, prefix);
}

XpbdOptions XpbdOptions::read(JsonFields& f) {
  XpbdOptions o;
  read_fields(xpbd_fields(), f, o, f.prefix());
  return o;
}

Json XpbdOptions::to_json() const {
  Json out = Json::object();
  write_fields(xpbd_fields(), *this, out);
  return out;
}

}  // namespace jelly
