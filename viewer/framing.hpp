#pragma once
// Where the default camera looks from: a box framed whole from the viewer's direction, raised
// above the horizontal until the obstacles (a bowl's wall, a box) no longer hide the bodies or
// the places straight below them where they will land. The live window, the replay and `jelly
// render` all start from it.
#include <vector>

#include <Eigen/Geometry>

#include <jelly/core/types.hpp>
#include <jelly/terrain/terrain.hpp>
#include <jelly/viewer/camera.hpp>

namespace jelly::viewer {

// Points the camera must see when its target is moved by `shift` (as a following camera moves
// it with the bodies).
struct Sight {
  Eigen::Vector3f shift = Eigen::Vector3f::Zero();
  std::vector<Eigen::Vector3f> points;
};

// Appends up to `count` of the particles x (evenly spaced through them) and, for each, the
// point just above the highest terrain surface straight below it (where it would land).
void add_sight_points(const VecX& x, const Terrains& terrains, Real t, int count,
                      std::vector<Eigen::Vector3f>& out);

// The camera that frames particles in [lo, hi] and the ground below their centre (the first
// terrain surface straight down), from the viewer's default direction (yaw -20 degrees), at
// the lowest pitch from 18 degrees up at which the terrains that are not ground planes hide at
// most 5 % of the sights' points (the least hidden pitch when none does). Without sights or
// obstacles: pitch 18. with_ground false: [lo, hi] alone (a camera that follows the bodies
// keeps them large; the ground shows around them anyway).
Camera framing_camera(const Vec3& lo, const Vec3& hi, const Terrains& terrains, Real t,
                      float aspect, const std::vector<Sight>& sights = {}, bool with_ground = true);

}  // namespace jelly::viewer
