#pragma once
// The kind-specific part of a body's description (a subclass per body kind: the cube's n, a
// mesh file and spacing, ...): it validates itself, builds the body's particles, springs and
// surface for a material, and writes itself back as JSON. The registry (body_kinds.hpp)
// reads it.
#include <memory>
#include <string>
#include <string_view>

#include <jelly/core/body.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/geometry/lattice.hpp>

namespace jelly {

class BodyShape {
 public:
  virtual ~BodyShape() = default;
  virtual std::string_view kind() const = 0;
  virtual std::unique_ptr<BodyShape> clone() const = 0;
  // Throws InputError naming `prefix`field (a scene passes its JSON path, "bodies[0].").
  virtual void validate(const std::string& prefix) const = 0;
  // The body's particles (masses from `material`), springs and render surface. Throws
  // InputError naming `prefix`field for input that only building reveals (an empty mesh,
  // too few or too many particles).
  virtual BodyPart build(const Material& material, const std::string& prefix) const = 0;
  // Upper bound on the particles build() makes, known before building (memory checks).
  virtual long estimated_particles() const = 0;
  // Estimate of the springs build() makes (memory checks): the lattice's 13 per particle unless
  // the kind knows better.
  virtual long estimated_springs() const { return 13 * estimated_particles(); }
  // Writes the kind's own keys into `object`.
  virtual void write(Json& object) const = 0;
};

// Implements clone() for a shape class.
template <typename Derived>
class BodyShapeOf : public BodyShape {
 public:
  std::unique_ptr<BodyShape> clone() const override {
    return std::make_unique<Derived>(static_cast<const Derived&>(*this));
  }
};

}  // namespace jelly
