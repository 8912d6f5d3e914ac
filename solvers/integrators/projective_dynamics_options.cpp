#include <jelly/solvers/integrators/projective_dynamics_options.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

namespace jelly {

const std::vector<EnumName<PositionContactMode>>& position_contact_modes() {
  static const std::vector<EnumName<PositionContactMode>> table{
      {PositionContactMode::kProjection, "projection",
       "contact and friction inside the step, by projection"},
      {PositionContactMode::kAfterStep, "after_step",
       "the explicit integrators' resolve after the step"},
  };
  return table;
}

void ProjectiveDynamicsOptions::validate(const std::string& prefix) const {
  require(iterations >= 1 && iterations <= 10000, prefix + "iterations", iterations,
          "an integer in [1, 10000]");
  require(std::isfinite(tolerance) && tolerance >= 0 && tolerance < 1, prefix + "tolerance",
          tolerance, "a relative residual in [0, 1) (0 = always run every iteration)");
  require(std::isfinite(chebyshev_rho) && chebyshev_rho >= 0 && chebyshev_rho < 1,
          prefix + "chebyshev_rho", chebyshev_rho, "a spectral radius in [0, 1) (0 = measured)");
  require(std::isfinite(chebyshev_gamma) && chebyshev_gamma > 0 && chebyshev_gamma <= 1,
          prefix + "chebyshev_gamma", chebyshev_gamma, "a relaxation in (0, 1]");
  require(chebyshev_delay >= 1, prefix + "chebyshev_delay", chebyshev_delay, "an integer >= 1");
  require(name_of(position_contact_modes(), contact) != "unknown", prefix + "contact",
          static_cast<int>(contact), "one of " + quoted_names(position_contact_modes()));
  require(name_of(cholmod_orderings(), ordering) != "unknown", prefix + "ordering",
          static_cast<int>(ordering), "one of " + quoted_names(cholmod_orderings()));
}

}  // namespace jelly

namespace jelly {

ProjectiveDynamicsOptions ProjectiveDynamicsOptions::read(JsonFields& f) {
  ProjectiveDynamicsOptions o;
  const auto choice = [&f](const auto& table, const char* key, auto value) {
    const std::string name = f.string_or(key, std::string(name_of(table, value)));
    return value_of(table, name, f.path(key));
  };
  o.iterations = f.integer_or("iterations", o.iterations);
  o.tolerance = f.number_or("tolerance", o.tolerance);
  o.chebyshev = f.boolean_or("chebyshev", o.chebyshev);
  o.chebyshev_rho = f.number_or("chebyshev_rho", o.chebyshev_rho);
  o.chebyshev_gamma = f.number_or("chebyshev_gamma", o.chebyshev_gamma);
  o.chebyshev_delay = f.integer_or("chebyshev_delay", o.chebyshev_delay);
  o.contact = choice(position_contact_modes(), "contact", o.contact);
  o.ordering = choice(cholmod_orderings(), "ordering", o.ordering);
  o.validate(f.prefix());
  return o;
}

Json ProjectiveDynamicsOptions::to_json() const {
  Json out = Json::object();
  out["iterations"] = iterations;
  out["tolerance"] = tolerance;
  out["chebyshev"] = chebyshev;
  out["chebyshev_rho"] = chebyshev_rho;
  out["chebyshev_gamma"] = chebyshev_gamma;
  out["chebyshev_delay"] = chebyshev_delay;
  out["contact"] = std::string(name_of(position_contact_modes(), contact));
  out["ordering"] = std::string(name_of(cholmod_orderings(), ordering));
  return out;
}

}  // namespace jelly
