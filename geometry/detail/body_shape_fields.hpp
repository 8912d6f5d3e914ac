#pragma once
// The field tables of bodies (core/detail/field_table.hpp), declared in their .cpp files: the
// keys every body has (body_spec.cpp), a spring type's coefficients (lattice.cpp), and each
// body kind's own keys. The row factories below declare the keys several tables share (a
// pose's, a material's) once.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/geometry/body_spec.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/detail/box.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/geometry/detail/voxelized.hpp>

namespace jelly {

const FieldTable<BodySpec>& body_fields();  // geometry/body_spec.cpp
const FieldTable<PinSpec>& pin_fields();    // geometry/body_spec.cpp
// The table of one external force kind (its keys differ: force, or velocity and drag).
const FieldTable<ExternalForceSpec>& external_force_fields(ExternalForceKind kind);
const FieldTable<SpringCoefficients>& spring_fields();       // geometry/lattice.cpp
const FieldTable<Material>& material_fields();               // geometry/lattice.cpp
const FieldTable<Pose>& pose_fields();                       // geometry/pose.cpp
const FieldTable<CubeShape>& cube_shape_fields();            // geometry/cube.cpp
const FieldTable<BoxShape>& box_shape_fields();              // geometry/box.cpp
const FieldTable<ClothShape>& cloth_shape_fields();          // geometry/cloth.cpp
const FieldTable<VoxelizedShape>& voxelized_shape_fields();  // geometry/voxelized.cpp
const FieldTable<TetmeshShape>& tetmesh_shape_fields();      // geometry/tetmesh.cpp

// A pose's keys (geometry/detail/pose.hpp), for a member path ending at a Pose's member.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> pose_scale_field() {
  return number_field<Ms...>("scale", "", range_above(0), "a finite scale > 0",
                             "Factor on the mesh's coordinates");
}
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> pose_position_field(std::string_view help) {
  return vec3_field<Ms...>("position", "m", range_finite(), "finite coordinates", help);
}
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> pose_rotation_field() {
  return vec3_field<Ms...>("rotation_degrees", "degrees", range_finite(), "finite angles (degrees)",
                           "Rotation about x, then y, then z (axes fixed in space)");
}

// A material's keys (geometry/body_shape.hpp).
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> particle_mass_field() {
  return number_field<Ms...>("particle_mass", "kg", range_above(0), "a finite mass > 0",
                             "Mass of each particle when density is 0");
}
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> density_field() {
  return number_field<Ms...>("density", "kg/m^3", range_at_least(0),
                             "a finite density >= 0 (0 = use particle_mass)",
                             "Mass per volume (a cloth: per area, kg/m^2); 0 = particle_mass");
}

}  // namespace jelly
