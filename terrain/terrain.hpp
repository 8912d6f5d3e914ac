#pragma once
// A rigid obstacle whose motion is a prescribed function of time t, with the contact model that
// answers particles touching it. Queries are per particle, never per spring.
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>
#include <jelly/geometry/triangle_mesh.hpp>

// How a terrain answers a particle that touches it: the contact model and its coefficients.
namespace jelly {

// How a terrain answers a particle that touches it.
enum class ContactModel {
  // Impulses on the relative velocity: restitution above a resting speed, Coulomb friction
  // (static and kinetic, bounded by mu times the normal impulse), penetration projected out.
  kCoulomb,
  // The seed report's rules (sections 1.2 and 1.3): velocity reflection within epsilon, a contact
  // force cancelling the inward force, and friction -mu N v_t proportional to the speed.
  // Reflection once after each step, the forces during the next one (any integrator).
  kSeed,
  // The same rules where the course framework applied them: inside every force evaluation, on
  // that evaluation's own state (each stage of a multi-stage method reflects its own velocity).
  // The explicit integrators only (docs/contact.md).
  kSeedFramework,
};
// Every contact model with its name and description.
const std::vector<EnumName<ContactModel>>& contact_models();
std::string_view contact_model_name(ContactModel model);  // "coulomb", "seed", "seed_framework"
// Throws InputError naming `field` for an unknown name.
ContactModel contact_model_from_name(std::string_view name, std::string_view field);
// The seed rules (either placement): reflection within epsilon, no projection.
inline bool is_seed_model(ContactModel model) {
  return model == ContactModel::kSeed || model == ContactModel::kSeedFramework;
}

// The contact model of a terrain and its coefficients.
struct ContactParams {
  ContactModel model = ContactModel::kCoulomb;  // coulomb, seed or seed_framework
  Real restitution = 0.8;                       // in [0, 1]
  Real friction = 0.5;         // kinetic mu (coulomb), the report's coefFriction (seed); >= 0
  Real static_friction = 0.5;  // coulomb: sticking when |v_t| <= mu_s * dv_n; >= friction
  Real epsilon = 0.01;         // seed: contact distance (m); > 0
  // coulomb: a particle bounces only if it was already approaching the surface faster than this
  // at the start of the step; an approach built up within one step (a resting particle pulled
  // down by gravity and its springs) is absorbed, so that a resting jelly does not jitter.
  Real resting_speed = 0.05;

  // Throws InputError naming `prefix`field for a value out of range.
  void validate(const std::string& prefix) const;
  // Reads the keys of a scene's "contact" object (missing keys keep their defaults), validated.
  static ContactParams read(JsonFields& fields);
  Json to_json() const;  // the scene's "contact" object that read() reads back
};

}  // namespace jelly

namespace jelly {

// A terrain or obstacle: its signed distance, normal and surface velocity at time t, and the
// contact model that answers particles touching it.
class Terrain {
 public:
  // A terrain that answers with `contact`.
  explicit Terrain(ContactParams contact) : contact_(contact) {}
  virtual ~Terrain() = default;

  // The terrain kind's name in scenes ("plane", "sphere", ...).
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
  virtual Eigen::Transform<Real, 3, Eigen::Isometry> pose(Real t) const;  // Isometry3d
  // The kind's dimensions as named numbers (a recording stores them as attributes).
  virtual std::vector<std::pair<std::string, Real>> attributes() const { return {}; }

  // Its contact model and coefficients.
  const ContactParams& contact() const { return contact_; }
  // Replaces its contact parameters; throws InputError for a value out of range.
  void set_contact(const ContactParams& contact);

 private:
  ContactParams contact_;
};

// A scene's terrains, in order (indices name them in messages and snapshots).
using Terrains = std::vector<std::unique_ptr<Terrain>>;

}  // namespace jelly
