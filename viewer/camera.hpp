#pragma once
// An orbit camera: it looks at `target` from `distance` away, turned by yaw about the vertical
// (y) axis and raised by pitch. Its view and projection matrices follow OpenGL's conventions;
// project() and ray() map between the world and the pixels of a width x height image (origin at
// the top-left corner, x right, y down, pixel (i, j) covering [i, i + 1) x [j, j + 1)).
#include <optional>
#include <string>

#include <Eigen/Core>

namespace jelly::viewer {

struct Camera {
  Eigen::Vector3f target = Eigen::Vector3f::Zero();
  float distance = 15;       // m, > 0
  float yaw_degrees = -35;   // about +y; 0 looks along -z
  float pitch_degrees = 20;  // above the horizontal, in (-89, 89)
  float fov_y_degrees = 40;  // vertical field of view
  // The picture's centre moved right by this fraction of its half-width (an off-centre
  // projection: the window shifts the view away from its panel).
  float shift_x = 0;

  Eigen::Vector3f eye() const;
  // Unit vectors of the camera's frame in the world.
  Eigen::Vector3f forward() const;
  Eigen::Vector3f right() const;
  Eigen::Vector3f up() const;
  float near_plane() const;
  float far_plane() const;

  Eigen::Matrix4f view() const;
  Eigen::Matrix4f projection(float aspect) const;

  // The pixel a world point lands on, or nothing when it is behind the camera.
  std::optional<Eigen::Vector2f> project(const Eigen::Vector3f& p, int width, int height) const;
  // The ray through pixel position (px, py): origin on the near plane, unit direction.
  void ray(float px, float py, int width, int height, Eigen::Vector3f& origin,
           Eigen::Vector3f& direction) const;

  // Mouse motions: orbit by degrees, pan by pixels of an image `height` tall, zoom by a factor
  // (< 1 moves closer).
  void orbit(float dyaw_degrees, float dpitch_degrees);
  void pan(float dx_pixels, float dy_pixels, int height);
  void zoom(float factor);

  // "yaw,pitch,distance" or "yaw,pitch,distance,tx,ty,tz" (degrees and metres); the fields left
  // out keep their values. Throws InputError naming `field` for anything else.
  void parse(const std::string& text, const std::string& field = "--camera");
  std::string to_string() const;
};

// A camera at the given yaw and pitch that shows the box [lo, hi] whole in an image of the given
// aspect (width / height), with a margin.
Camera frame_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float aspect,
                 float yaw_degrees = -35, float pitch_degrees = 20);

}  // namespace jelly::viewer
