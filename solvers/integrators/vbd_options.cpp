#include <jelly/solvers/integrators/integrator_options.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>

namespace jelly {

const FieldTable<VbdOptions>& vbd_fields() {
  using O = VbdOptions;
  static const FieldTable<O> table{
      "VbdOptions",
      "integrator.options",
      "Options of vbd (docs/realtime.md)",
      {
          integer_field<&O::iterations>("iterations", "", range_closed(1, 10000),
                                        "an integer in [1, 10000]",
                                        "Sweeps over all colours per step"),
          number_field<&O::chebyshev_rho>(
              "chebyshev_rho", "", range_closed_open(0, 1),
              "a number in [0, 1) (0 = no acceleration)",
              "Spectral radius estimate of the Chebyshev acceleration; 0 = off"),
          number_field<&O::damping>("damping", "s", range_at_least(0),
                                    "a time >= 0 s (0 = only the springs' dampers)",
                                    "The paper's Rayleigh-type damping on each particle's "
                                    "springs' Hessian; the springs' kd always act"),
          number_field<&O::contact_hardness>(
              "contact_hardness", "", range_closed(0, 1e8),
              "a number in [0, 1e8] (0 = contact only after the step)",
              "Experimental penalty contact with coulomb terrains inside the sweeps "
              "(k = contact_hardness m / h^2); 0 = contact after the step"),
      },
  };
  return table;
}

void VbdOptions::validate(const std::string& prefix) const {
  validate_fields(vbd_fields(), *this, prefix);
}

VbdOptions VbdOptions::read(JsonFields& f) {
  VbdOptions o;
  read_fields(vbd_fields(), f, o, f.prefix());
  return o;
}

Json VbdOptions::to_json() const {
  Json out = Json::object();
  write_fields(vbd_fields(), *this, out);
  return out;
}

}  // namespace jelly
