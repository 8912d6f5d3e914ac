// The contact models, one line each: a new model is its own file (a TerrainContactModel and a
// function giving it), its declaration and line here, and its value in ContactModel with a row
// of contact_models() (terrain/contact_params.cpp).
#include <jelly/solvers/contact/terrain_contact_model.hpp>

#include <stdexcept>

namespace jelly {

const TerrainContactModel& coulomb_contact_model();
const TerrainContactModel& seed_contact_model();
const TerrainContactModel& seed_framework_contact_model();

const TerrainContactModel& terrain_contact_model(ContactModel kind) {
  using Entry = const TerrainContactModel& (*)();
  static const Entry models[] = {
      &coulomb_contact_model,
      &seed_contact_model,
      &seed_framework_contact_model,
  };
  for (Entry entry : models) {
    const TerrainContactModel& model = entry();
    if (model.kind() == kind) return model;
  }
  throw std::logic_error("terrain_contact_model: no model registered for contact model " +
                         std::string(contact_model_name(kind)));
}

}  // namespace jelly
