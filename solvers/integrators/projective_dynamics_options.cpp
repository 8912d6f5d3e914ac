#include <jelly/solvers/integrators/integrator_options.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>

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

const FieldTable<ProjectiveDynamicsOptions>& projective_dynamics_fields() {
  using O = ProjectiveDynamicsOptions;
  static const FieldTable<O> table{
      "ProjectiveDynamicsOptions",
      "integrator.options",
      "Options of projective_dynamics (docs/realtime.md)",
      {
          integer_field<&O::iterations>("iterations", "", range_closed(1, 10000),
                                        "an integer in [1, 10000]",
                                        "Local/global iterations per step"),
          number_field<&O::tolerance>(
              "tolerance", "", range_closed_open(0, 1),
              "a relative residual in [0, 1) (0 = always run every iteration)",
              "Relative residual that ends a step early; 0 = always run `iterations`"),
          boolean_field<&O::chebyshev>("chebyshev",
                                       "Chebyshev acceleration (Wang 2015) of the iterations"),
          number_field<&O::chebyshev_rho>("chebyshev_rho", "", range_closed_open(0, 1),
                                          "a spectral radius in [0, 1) (0 = measured)",
                                          "Spectral radius of the plain iteration; 0 = measured "
                                          "during the first step"),
          number_field<&O::chebyshev_gamma>("chebyshev_gamma", "", range_open_closed(0, 1),
                                            "a relaxation in (0, 1]",
                                            "Under-relaxation of the accelerated update"),
          integer_field<&O::chebyshev_delay>(
              "chebyshev_delay", "", range_at_least(1), "an integer >= 1",
              "Plain iterations of each step before the acceleration starts"),
          choice_field<&O::contact, &position_contact_modes>("contact",
                                                             "How coulomb terrains enter the step"),
          choice_field<&O::ordering, &cholmod_orderings>(
              "ordering", "Fill-reducing ordering of the CHOLMOD factor"),
      },
  };
  return table;
}

void ProjectiveDynamicsOptions::validate(const std::string& prefix) const {
  validate_fields(projective_dynamics_fields(), *this, prefix);
}

ProjectiveDynamicsOptions ProjectiveDynamicsOptions::read(JsonFields& f) {
  ProjectiveDynamicsOptions o;
  read_fields(projective_dynamics_fields(), f, o, f.prefix());
  return o;
}

Json ProjectiveDynamicsOptions::to_json() const {
  Json out = Json::object();
  write_fields(projective_dynamics_fields(), *this, out);
  return out;
}

}  // namespace jelly
