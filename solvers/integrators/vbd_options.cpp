#include <jelly/solvers/integrators/vbd_options.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

namespace jelly {

void VbdOptions::validate(const std::string& prefix) const {
  require(iterations >= 1 && iterations <= 10000, prefix + "iterations", iterations,
          "an integer in [1, 10000]");
  require(std::isfinite(chebyshev_rho) && chebyshev_rho >= 0 && chebyshev_rho < 1,
          prefix + "chebyshev_rho", chebyshev_rho, "a number in [0, 1) (0 = no acceleration)");
  require(std::isfinite(damping) && damping >= 0, prefix + "damping", damping,
          "a time >= 0 s (0 = only the springs' dampers)");
  require(std::isfinite(contact_hardness) && contact_hardness >= 0 && contact_hardness <= 1e8,
          prefix + "contact_hardness", contact_hardness,
          "a number in [0, 1e8] (0 = contact only after the step)");
}

VbdOptions VbdOptions::read(JsonFields& f) {
  VbdOptions o;
  o.iterations = f.integer_or("iterations", o.iterations);
  o.chebyshev_rho = f.number_or("chebyshev_rho", o.chebyshev_rho);
  o.damping = f.number_or("damping", o.damping);
  o.contact_hardness = f.number_or("contact_hardness", o.contact_hardness);
  o.validate(f.prefix());
  return o;
}

Json VbdOptions::to_json() const {
  Json out = Json::object();
  out["iterations"] = iterations;
  out["chebyshev_rho"] = chebyshev_rho;
  out["damping"] = damping;
  out["contact_hardness"] = contact_hardness;
  return out;
}

}  // namespace jelly
