#pragma once
// Body kind "box": a lattice of nx x ny x nz particles filling a box of the given size, centred
// at the pose's position and rotated by it.
#include <array>

#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/pose.hpp>

namespace jelly {

struct BoxShape final : BodyShapeOf<BoxShape> {
  std::array<int, 3> n{4, 4, 4};  // particles along x, y, z, each >= 2
  Vec3 size = Vec3::Ones();       // m along x, y, z, each > 0
  Pose pose;                      // position = the box's centre; scale not allowed

  std::string_view kind() const override { return "box"; }
  void validate(const std::string& prefix) const override;
  BodyPart build(const Material& material, const std::string& prefix) const override;
  long estimated_particles() const override {
    return static_cast<long>(n[0]) * n[1] * static_cast<long>(n[2]);
  }
  void write(Json& object) const override;
  static std::unique_ptr<BodyShape> read(JsonFields& fields);
};

}  // namespace jelly
