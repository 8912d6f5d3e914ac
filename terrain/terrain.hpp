#pragma once
// A rigid obstacle whose motion is a prescribed function of time t, with the contact model that
// answers particles touching it. Queries are per particle, never per spring.
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <jelly/core/types.hpp>
#include <jelly/geometry/triangle_mesh.hpp>
#include <jelly/terrain/contact_params.hpp>

namespace jelly {

class Terrain {
 public:
  explicit Terrain(ContactParams contact) : contact_(contact) {}
  virtual ~Terrain() = default;

  virtual std::string_view kind() const = 0;
  // Distance of p above the surface at time t: > 0 outside, < 0 penetrating.
  virtual Real signed_distance(const Vec3& p, Real t) const = 0;
  // Outward unit normal of the surface nearest p.
  virtual Vec3 normal(const Vec3& p, Real t) const = 0;
  // Velocity of the surface point nearest p.
  virtual Vec3 surface_velocity(const Vec3& p, Real t) const = 0;
  // Whether a particle at p can touch the surface: inside the footprint, not far below it.
  virtual bool can_contact(const Vec3& p, Real t) const = 0;
  // A reference point that moves with the terrain (recorded as its position).
  virtual Vec3 position(Real t) const = 0;
  // Mass in the seed collision formula; infinite for a fixed terrain.
  virtual Real mass() const { return std::numeric_limits<Real>::infinity(); }
  // The terrain's shape for drawing and export, in its own frame (a plane: a large square).
  virtual TriangleMesh render_mesh() const = 0;
  // Where render_mesh() is at time t: its rigid placement in the world.
  virtual Eigen::Isometry3d pose(Real t) const;
  // The kind's dimensions as named numbers (a recording stores them as attributes).
  virtual std::vector<std::pair<std::string, Real>> attributes() const { return {}; }

  const ContactParams& contact() const { return contact_; }
  void set_contact(const ContactParams& contact);

 private:
  ContactParams contact_;
};

// A scene's terrains, in order (indices name them in messages and snapshots).
using Terrains = std::vector<std::unique_ptr<Terrain>>;

}  // namespace jelly
