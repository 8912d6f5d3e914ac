#include <jelly/viewer/camera.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include <Eigen/Geometry>

#include <jelly/core/errors.hpp>

namespace jelly::viewer {

namespace {

constexpr float kDegrees = 3.14159265358979f / 180.0f;

}  // namespace

Eigen::Vector3f Camera::eye() const { return target - distance * forward(); }

Eigen::Vector3f Camera::forward() const {
  const float yaw = yaw_degrees * kDegrees, pitch = pitch_degrees * kDegrees;
  // From the eye towards the target.
  return Eigen::Vector3f(-std::cos(pitch) * std::sin(yaw), -std::sin(pitch),
                         -std::cos(pitch) * std::cos(yaw));
}

Eigen::Vector3f Camera::right() const {
  return forward().cross(Eigen::Vector3f::UnitY()).normalized();
}

Eigen::Vector3f Camera::up() const { return right().cross(forward()); }

float Camera::near_plane() const { return std::max(0.01f, 0.02f * distance); }
float Camera::far_plane() const { return 200.0f * distance + 100.0f; }

Eigen::Matrix4f Camera::view() const {
  const Eigen::Vector3f f = forward(), r = right(), u = up(), e = eye();
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.row(0).head<3>() = r;
  m.row(1).head<3>() = u;
  m.row(2).head<3>() = -f;
  m(0, 3) = -r.dot(e);
  m(1, 3) = -u.dot(e);
  m(2, 3) = f.dot(e);
  return m;
}

Eigen::Matrix4f Camera::projection(float aspect) const {
  const float n = near_plane(), f = far_plane();
  const float t = 1.0f / std::tan(0.5f * fov_y_degrees * kDegrees);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = t / aspect;
  m(0, 2) = -shift_x;  // x_ndc = t / aspect * x / -z + shift_x
  m(1, 1) = t;
  m(2, 2) = (f + n) / (n - f);
  m(2, 3) = 2 * f * n / (n - f);
  m(3, 2) = -1;
  return m;
}

std::optional<Eigen::Vector2f> Camera::project(const Eigen::Vector3f& p, int width,
                                               int height) const {
  const Eigen::Vector4f clip = projection(static_cast<float>(width) / static_cast<float>(height)) *
                               view() * Eigen::Vector4f(p.x(), p.y(), p.z(), 1);
  if (clip.w() <= 0) return std::nullopt;
  const float x = clip.x() / clip.w(), y = clip.y() / clip.w();
  return Eigen::Vector2f((0.5f * x + 0.5f) * static_cast<float>(width),
                         (0.5f - 0.5f * y) * static_cast<float>(height));
}

void Camera::ray(float px, float py, int width, int height, Eigen::Vector3f& origin,
                 Eigen::Vector3f& direction) const {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const float x = 2 * px / static_cast<float>(width) - 1 - shift_x;
  const float y = 1 - 2 * py / static_cast<float>(height);
  const float t = std::tan(0.5f * fov_y_degrees * kDegrees);
  direction = (forward() + x * t * aspect * right() + y * t * up()).normalized();
  origin = eye() + near_plane() * direction / direction.dot(forward());
}

void Camera::orbit(float dyaw_degrees, float dpitch_degrees) {
  yaw_degrees = std::fmod(yaw_degrees + dyaw_degrees, 360.0f);
  pitch_degrees = std::clamp(pitch_degrees + dpitch_degrees, -89.0f, 89.0f);
}

void Camera::pan(float dx_pixels, float dy_pixels, int height) {
  const float scale =
      2 * distance * std::tan(0.5f * fov_y_degrees * kDegrees) / static_cast<float>(height);
  target += scale * (-dx_pixels * right() + dy_pixels * up());
}

void Camera::zoom(float factor) { distance = std::clamp(distance * factor, 0.05f, 1e5f); }

void Camera::parse(const std::string& text, const std::string& field) {
  std::vector<float> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const float v = std::strtof(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v))
      throw InputError(field, text, "yaw,pitch,distance[,tx,ty,tz] (degrees, metres)");
    values.push_back(v);
  }
  if ((values.size() != 3 && values.size() != 6) || values[2] <= 0 || std::abs(values[1]) >= 89.5f)
    throw InputError(field, text,
                     "yaw,pitch,distance[,tx,ty,tz] (degrees, metres; |pitch| < 89.5, "
                     "distance > 0)");
  yaw_degrees = values[0];
  pitch_degrees = values[1];
  distance = values[2];
  if (values.size() == 6) target = Eigen::Vector3f(values[3], values[4], values[5]);
}

std::string Camera::to_string() const {
  char text[160];
  std::snprintf(text, sizeof text, "%.4g,%.4g,%.4g,%.4g,%.4g,%.4g", yaw_degrees, pitch_degrees,
                distance, target.x(), target.y(), target.z());
  return text;
}

Camera frame_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float aspect,
                 float yaw_degrees, float pitch_degrees) {
  Camera c;
  c.yaw_degrees = yaw_degrees;
  c.pitch_degrees = pitch_degrees;
  c.target = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * (hi - lo).norm(), 0.1f);
  const float half_y = 0.5f * c.fov_y_degrees * kDegrees;
  const float half_x = std::atan(std::tan(half_y) * aspect);
  c.distance = 1.1f * radius / std::sin(std::min(half_x, half_y));
  return c;
}

}  // namespace jelly::viewer
