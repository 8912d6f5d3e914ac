#pragma once
// A terrain of one's own: a rippled floor y = amplitude sin(2 pi x / wavelength), with the
// contact model of its ContactParams (coulomb by default), as a peer of jelly's planes.
#include <cmath>
#include <string_view>

#include <jelly/jelly.hpp>

class RippleFloor final : public jelly::Terrain {
 public:
  RippleFloor(double amplitude, double wavelength, jelly::ContactParams contact = {})
      : Terrain(contact), amplitude_(amplitude), k_(2 * M_PI / wavelength) {}

  std::string_view kind() const override { return "ripple_floor"; }

  // The height above the surface along its normal, to first order in the slope.
  double signed_distance(const Eigen::Vector3d& p, double /*t*/) const override {
    const double slope = amplitude_ * k_ * std::cos(k_ * p.x());
    return (p.y() - height(p.x())) / std::sqrt(1 + slope * slope);
  }
  Eigen::Vector3d normal(const Eigen::Vector3d& p, double /*t*/) const override {
    return Eigen::Vector3d(-amplitude_ * k_ * std::cos(k_ * p.x()), 1, 0).normalized();
  }
  Eigen::Vector3d surface_velocity(const Eigen::Vector3d& /*p*/, double /*t*/) const override {
    return Eigen::Vector3d::Zero();
  }
  bool can_contact(const Eigen::Vector3d& /*p*/, double /*t*/) const override { return true; }
  Eigen::Vector3d position(double /*t*/) const override { return Eigen::Vector3d::Zero(); }

  // A strip of quads 20 m square, 64 along x, for drawing and export.
  jelly::TriangleMesh render_mesh() const override {
    jelly::TriangleMesh mesh;
    constexpr int kCells = 64;
    for (int i = 0; i <= kCells; ++i) {
      const double x = -10 + 20.0 * i / kCells;
      mesh.vertices.emplace_back(x, height(x), -10);
      mesh.vertices.emplace_back(x, height(x), 10);
    }
    for (int i = 0; i < kCells; ++i) mesh.add_quad(2 * i, 2 * i + 1, 2 * i + 3, 2 * i + 2);
    return mesh;
  }

 private:
  double height(double x) const { return amplitude_ * std::sin(k_ * x); }

  double amplitude_, k_;
};
