#include <jelly/terrain/terrain.hpp>

namespace jelly {

void Terrain::set_contact(const ContactParams& contact) {
  contact.validate("contact.");
  contact_ = contact;
}

}  // namespace jelly
