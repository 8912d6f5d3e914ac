#pragma once
// The field tables of terrain kinds' specs (core/detail/field_table.hpp), declared in their
// .cpp files. Each table holds the kind's own keys; `kind` and `contact` are read by
// terrain_kinds.cpp. The row factories below declare keys several kinds share once.
#include <jelly/core/detail/field_table.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/detail/mesh_obstacle.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/detail/obstacle_motion.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {

const FieldTable<PlaneSpec>& plane_fields();        // terrain/plane.cpp
const FieldTable<SlopeSpec>& slope_fields();        // terrain/plane.cpp
const FieldTable<ElevatorSpec>& elevator_fields();  // terrain/elevator.cpp
// The table of one obstacle shape ("sphere", "box", "capsule", "cylinder").
const FieldTable<ObstacleSpec>& obstacle_fields(ObstacleShape shape);  // terrain/obstacle.cpp
const FieldTable<MeshObstacleSpec>& mesh_obstacle_fields();            // terrain/mesh_obstacle.cpp

// An obstacle's path (core/pins.hpp) and its spin.
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> obstacle_motion_field() {
  return json_value_field<Ms...>(
      "motion",
      "\"fixed\" or a path {\"kind\": phases, keyframes, oscillation, circle or linear, ...}",
      "The centre's path from where it starts (docs/scenes.md, paths)",
      R"({"kind": "oscillation", "amplitude": [0.0, 0.1, 0.0], "frequency": 1.0, "phase": 0.0})");
}
template <auto... Ms>
Field<field_detail::StructOf<Ms...>> obstacle_spin_field() {
  return vec3_field<Ms...>("angular_velocity_degrees", "degrees/s",
                           range_closed(0, kMaxAngularVelocityDegrees),
                           "finite rates (degrees per second) whose norm is at most 1e6 (about "
                           "2,800 turns a second)",
                           "Constant spin about the centre (about the world's x, y, z)");
}

}  // namespace jelly
