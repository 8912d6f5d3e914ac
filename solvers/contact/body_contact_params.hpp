#pragma once
// The parameters of contact between bodies and within a body (a scene's "body_contact" object,
// Simulator::set_body_contact; docs/contact.md): the public face of the internal BodyContact.
#include <string>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

// Contact between bodies and within a body (docs/contact.md): restitution, friction, passes.
struct BodyContactParams {
  bool enabled = true;         // contact between different bodies
  bool self_contact = false;   // contact between parts of one body that no spring joins
  Real restitution = 0.2;      // in [0, 1]
  Real friction = 0.5;         // kinetic mu >= 0
  Real static_friction = 0.5;  // >= friction
  Real resting_speed = 0.05;   // an approach slower than this (m/s) is absorbed, never reflected
  int iterations = 4;          // passes over the contact pairs per step, >= 1

  // Throws InputError naming `prefix`field.
  void validate(const std::string& prefix) const;
  // The keys of a scene's "body_contact" object (missing keys keep their defaults), validated.
  static BodyContactParams read(JsonFields& fields);
  Json to_json() const;  // the scene's "body_contact" object that read() reads back
};

}  // namespace jelly
