#include <jelly/terrain/detail/elevator.hpp>

#include <cmath>
#include <limits>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/terrain/detail/terrain_fields.hpp>

namespace jelly {

const FieldTable<ElevatorSpec>& elevator_fields() {
  using E = ElevatorSpec;
  static const FieldTable<E> table{
      "ElevatorSpec",
      "terrains[i]",
      "A moving platform (the seed's elevator): a box's top face moving along y",
      {
          vec3_field<&E::center>("center", "m", range_finite(), "finite coordinates",
                                 "The platform's centre at t = 0"),
          number_field<&E::size_x>("size_x", "m", range_above(0), "a finite size > 0",
                                   "Footprint along x"),
          number_field<&E::size_z>("size_z", "m", range_above(0), "a finite size > 0",
                                   "Footprint along z"),
          number_field<&E::thickness>("thickness", "m", range_above(0), "a finite thickness > 0",
                                      "How deep below the surface a particle still touches it"),
          number_or_inf_field<&E::mass>("mass", "kg", range_or_infinite(range_above(0)),
                                        "a mass > 0 (inf for an immovable platform)",
                                        "Platform mass in the seed's collision formula"),
          json_value_field<&E::motion>(
              "motion", "\"seed\" or a list of phases [{duration, acceleration, stop_at_end}]",
              "Constant-acceleration phases along y, repeated",
              R"([{"duration": 1.0, "acceleration": 2.0, "stop_at_end": false}, )"
              R"({"duration": 1.0, "acceleration": -2.0, "stop_at_end": true}])"),
      },
  };
  return table;
}

void ElevatorSpec::validate(const std::string& prefix) const {
  validate_fields(elevator_fields(), *this, prefix);
}

Elevator::Elevator(ElevatorSpec spec, ContactParams contact)
    : Terrain(contact), spec_(std::move(spec)) {
  spec_.validate("elevator.");
  contact.validate("contact.");
}

bool Elevator::can_contact(const Vec3& p, Real t) const {
  const Real d = signed_distance(p, t);
  return std::abs(p.x() - spec_.center.x()) <= 0.5 * spec_.size_x &&
         std::abs(p.z() - spec_.center.z()) <= 0.5 * spec_.size_z && d > -spec_.thickness;
}

TriangleMesh Elevator::render_mesh() const {
  TriangleMesh mesh = box_mesh(Vec3(spec_.size_x, spec_.thickness, spec_.size_z));
  for (Vec3& v : mesh.vertices) v.y() -= 0.5 * spec_.thickness;
  return mesh;
}

std::unique_ptr<Terrain> ElevatorSpec::make() const {
  return std::make_unique<Elevator>(*this, contact);
}

void ElevatorSpec::write(Json& j) const { write_fields(elevator_fields(), *this, j); }

std::unique_ptr<TerrainSpec> ElevatorSpec::read(JsonFields& f) {
  auto e = std::make_unique<ElevatorSpec>();
  read_fields(elevator_fields(), f, *e, f.prefix());
  return e;
}

}  // namespace jelly
