#include <jelly/terrain/terrain.hpp>

#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/contact_fields.hpp>

namespace jelly {

const std::vector<EnumName<ContactModel>>& contact_models() {
  static const std::vector<EnumName<ContactModel>> table{
      {ContactModel::kCoulomb, "coulomb",
       "projection, restitution above a resting speed, Coulomb friction (default)"},
      {ContactModel::kSeed, "seed",
       "the seed report's rules: reflection within epsilon, friction -mu N v_t"},
      {ContactModel::kSeedFramework, "seed_framework",
       "the seed rules inside every force evaluation, as the course framework (explicit "
       "integrators)"},
  };
  return table;
}

std::string_view contact_model_name(ContactModel model) { return name_of(contact_models(), model); }

ContactModel contact_model_from_name(std::string_view name, std::string_view field) {
  return value_of(contact_models(), name, field);
}

namespace {

void check_contact_friction(const ContactParams& c, const std::string& prefix) {
  require(c.static_friction >= c.friction, prefix + "static_friction", c.static_friction,
          "a finite number >= friction (" + to_text(c.friction) + ")");
}

}  // namespace

const FieldTable<ContactParams>& contact_params_fields() {
  using C = ContactParams;
  static const FieldTable<C> table{
      "ContactParams",
      "terrains[i].contact",
      "How a terrain answers a particle that touches it (docs/contact.md)",
      {
          choice_field<&C::model, &contact_models>("model", "The contact model"),
          number_field<&C::restitution>("restitution", "", range_closed(0, 1), "a number in [0, 1]",
                                        "Normal velocity kept, reversed, by a bounce"),
          number_field<&C::friction>("friction", "", range_at_least(0), "a finite number >= 0",
                                     "Kinetic mu (coulomb), the report's friction (seed)"),
          number_field<&C::static_friction>(
              "static_friction", "", range_finite(), "a finite number >= friction",
              "Coulomb: sticking while |v_t| <= static_friction dv_n; >= friction"),
          number_field<&C::epsilon>("epsilon", "m", range_above(0), "a finite distance > 0",
                                    "Seed: contact distance"),
          number_field<&C::resting_speed>("resting_speed", "m/s", range_at_least(0),
                                          "a finite speed >= 0",
                                          "Coulomb: the slowest approach that bounces"),
      },
      &check_contact_friction,
  };
  return table;
}

void ContactParams::validate(const std::string& prefix) const {
  validate_fields(contact_params_fields(), *this, prefix);
}

ContactParams ContactParams::read(JsonFields& f) {
  ContactParams c;
  read_fields(contact_params_fields(), f, c, f.prefix(), /*reject_unknown=*/true);
  return c;
}

Json ContactParams::to_json() const {
  Json j = Json::object();
  write_fields(contact_params_fields(), *this, j);
  return j;
}

}  // namespace jelly
