#pragma once
// Body kind "cloth": a rectangular sheet of nu x nv particles, lying in its local x-z plane
// (u along x, v along z, normal +y) centred at the pose's position and rotated by it; the seed's
// spring pattern in the plane: structural to the u and v neighbours, shear along both cell
// diagonals, bending to the neighbours at distance 2.
#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/pose.hpp>

namespace jelly {

struct ClothShape final : BodyShapeOf<ClothShape> {
  int nu = 10, nv = 10;         // particles along u and v, each >= 2
  Real size_u = 1, size_v = 1;  // m
  Pose pose;                    // position = the sheet's centre; scale not allowed

  std::string_view kind() const override { return "cloth"; }
  void validate(const std::string& prefix) const override;
  // Particle (i, j) has index i nv + j. A material density is per area (kg/m^2).
  BodyPart build(const Material& material, const std::string& prefix) const override;
  long estimated_particles() const override { return static_cast<long>(nu) * nv; }
  // Exactly the springs build() makes (structural, shear and bending along both directions).
  long estimated_springs() const override;
  void write(Json& object) const override;
  static std::unique_ptr<BodyShape> read(JsonFields& fields);
};

}  // namespace jelly
