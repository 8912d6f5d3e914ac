#include <jelly/terrain/contact_params.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

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

void ContactParams::validate(const std::string& prefix) const {
  require(std::isfinite(restitution) && restitution >= 0 && restitution <= 1,
          prefix + "restitution", restitution, "a number in [0, 1]");
  require(std::isfinite(friction) && friction >= 0, prefix + "friction", friction,
          "a finite number >= 0");
  require(std::isfinite(static_friction) && static_friction >= friction, prefix + "static_friction",
          static_friction, "a finite number >= friction (" + to_text(friction) + ")");
  require(std::isfinite(epsilon) && epsilon > 0, prefix + "epsilon", epsilon,
          "a finite distance > 0");
  require(std::isfinite(resting_speed) && resting_speed >= 0, prefix + "resting_speed",
          resting_speed, "a finite speed >= 0");
}

ContactParams ContactParams::read(JsonFields& f) {
  ContactParams c;
  c.model = contact_model_from_name(f.string_or("model", std::string(contact_model_name(c.model))),
                                    f.path("model"));
  c.restitution = f.number_or("restitution", c.restitution);
  c.friction = f.number_or("friction", c.friction);
  c.static_friction = f.number_or("static_friction", c.static_friction);
  c.epsilon = f.number_or("epsilon", c.epsilon);
  c.resting_speed = f.number_or("resting_speed", c.resting_speed);
  f.reject_unknown();
  c.validate(f.prefix());
  return c;
}

Json ContactParams::to_json() const {
  Json j;
  j["model"] = std::string(contact_model_name(model));
  j["restitution"] = restitution;
  j["friction"] = friction;
  j["static_friction"] = static_friction;
  j["epsilon"] = epsilon;
  j["resting_speed"] = resting_speed;
  return j;
}

}  // namespace jelly
