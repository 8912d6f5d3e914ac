#include <jelly/terrain/contact_params.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

std::string_view contact_model_name(ContactModel model) {
  return model == ContactModel::kSeed ? "seed" : "coulomb";
}

ContactModel contact_model_from_name(std::string_view name, std::string_view field) {
  if (name == "coulomb") return ContactModel::kCoulomb;
  if (name == "seed") return ContactModel::kSeed;
  throw InputError(field, "\"" + std::string(name) + "\"", "one of \"coulomb\", \"seed\"");
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

}  // namespace jelly
