#pragma once
// The seed elevator: a horizontal rectangular platform (normal +y) moving vertically by an
// ElevatorMotion. A particle outside its footprint, or deeper below it than its thickness,
// does not touch it and falls past.
#include <string>

#include <jelly/core/pins.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/terrain/terrain_kinds.hpp>

namespace jelly {

// Scene kind "elevator".
struct ElevatorSpec final : TerrainSpecOf<ElevatorSpec> {
  Vec3 center{0, 1, 0};  // platform centre at t = 0
  Real size_x = 5;       // footprint along x (m), > 0
  Real size_z = 5;       // footprint along z (m), > 0
  Real thickness = 1;    // how deep below the surface a particle still counts as touching (m)
  Real mass = 1;         // kg, the platform mass of the seed collision formula
  ElevatorMotion motion = ElevatorMotion::seed();

  std::string_view kind() const override { return "elevator"; }
  // Throws InputError naming `prefix`field (a scene passes its JSON path, "terrains[0].").
  void validate(const std::string& prefix) const override;
  std::unique_ptr<Terrain> make() const override;
  void write(Json& object) const override;
  static std::unique_ptr<TerrainSpec> read(JsonFields& fields);
};

class Elevator final : public Terrain {
 public:
  // Answers with the spec's own contact model (spec.contact).
  explicit Elevator(ElevatorSpec spec = {}) : Elevator(spec, spec.contact) {}
  Elevator(ElevatorSpec spec, ContactParams contact);

  std::string_view kind() const override { return "elevator"; }
  Real signed_distance(const Vec3& p, Real t) const override { return p.y() - height(t); }
  Vec3 normal(const Vec3& /*p*/, Real /*t*/) const override { return Vec3::UnitY(); }
  Vec3 surface_velocity(const Vec3& /*p*/, Real t) const override {
    return Vec3(0, spec_.motion.velocity(t), 0);
  }
  bool can_contact(const Vec3& p, Real t) const override;
  Vec3 position(Real t) const override {
    return Vec3(spec_.center.x(), height(t), spec_.center.z());
  }
  Real mass() const override { return spec_.mass; }
  // The platform: size_x by thickness by size_z, its top face at the surface.
  TriangleMesh render_mesh() const override;
  std::vector<std::pair<std::string, Real>> attributes() const override {
    return {{"size_x", spec_.size_x},
            {"size_z", spec_.size_z},
            {"thickness", spec_.thickness},
            {"mass", spec_.mass}};
  }

  Real height(Real t) const { return spec_.center.y() + spec_.motion.offset(t); }
  const ElevatorSpec& spec() const { return spec_; }

 private:
  ElevatorSpec spec_;
};

}  // namespace jelly
