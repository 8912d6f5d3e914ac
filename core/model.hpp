#pragma once
// The mass-spring model: particle masses, springs with dampers (struct-of-arrays), gravity, and
// the bodies they form, with pinned particles and external forces.
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/body.hpp>
#include <jelly/core/external_force.hpp>
#include <jelly/core/pins.hpp>
#include <jelly/core/springs.hpp>
#include <jelly/core/state.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct Model {
  VecX mass;           // [N] particle masses (kg)
  VecX rest_position;  // [3N] the positions the rest lengths were measured in
  Springs springs;
  Vec3 gravity{0, -9.8, 0};
  // Named ranges of particles and springs, in order; together they cover all of them.
  std::vector<Body> bodies;
  Pins pins;
  std::vector<ExternalForce> external_forces;

  int num_particles() const { return static_cast<int>(mass.size()); }
  int num_dofs() const { return 3 * num_particles(); }
  int num_bodies() const { return static_cast<int>(bodies.size()); }

  // Appends a body built by a builder: its particles and springs after the existing ones.
  // `radius` <= 0 takes half the part's spacing; the body's thickness is its radius for a sheet
  // (BodyPart::sheet), else 0. Returns the body's index. Throws InputError
  // for a duplicate or empty name or an inconsistent part.
  int add_body(const std::string& name, BodyPart part, Real radius = 0);
  // The body named `name`, or nullptr.
  const Body* find_body(std::string_view name) const;
  // The body that holds particle i.
  const Body& body_of(int particle) const;

  // Throws InputError when a mass, index, rest length or coefficient is out of range.
  void validate() const;
};

// The model at rest in its construction pose, at time 0.
State rest_state(const Model& model);
// The model in its construction pose at time 0, each body moving as its velocity and
// angular_velocity say (at rest when they are zero).
State initial_state(const Model& model);

}  // namespace jelly
