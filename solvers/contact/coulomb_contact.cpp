// The coulomb contact model: projection out of the surface, then an impulse on the relative
// velocity; implicit_euler's solve and the position-based integrators hold it as constraints.
#include <jelly/solvers/contact/detail/thickness.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>

namespace jelly {

namespace {

class CoulombModel final : public TerrainContactModel {
 public:
  ContactModel kind() const override { return ContactModel::kCoulomb; }
  bool constrains_solves() const override { return true; }

  int resolve_after_step(const AfterStepContact& step, int begin, int end,
                         std::vector<CarriedContact>& /*carried*/) const override {
    int count = 0;
    thickness::for_ranges(step.model, begin, end, [&](int first, int last, Real gap) {
      for (int i = first; i < last; ++i)
        count += resolve(step.terrain, step.params, step.state.t, step.h, gap,
                         particle(step.before.x, i), particle(step.before.v, i),
                         particle(step.state.x, i), particle(step.state.v, i));
    });
    return count;
  }

 private:
  // Normal: restitution e when the particle approached faster than the resting speed at the
  // start of the step (v_before), else the normal relative speed is absorbed.
  // Tangential: sticks when |v_t| <= mu_s dv_n, else slides with |v_t| reduced by mu dv_n, so
  // the friction impulse never exceeds mu times the normal impulse. Friction acts during the
  // step, so the tangential displacement it removes is taken back too: a sticking particle keeps
  // its tangential position relative to the surface (x_before + u h), a sliding one loses
  // h dv_t. Without that, the velocity-level friction leaves a creep of h a_t / 2 per unit time.
  // The particle keeps `gap` (its body's thickness) from the surface.
  static bool resolve(const Terrain& terrain, const ContactParams& c, Real t, Real h, Real gap,
                      const Vec3& x_before, const Vec3& v_before, Eigen::Ref<Vec3> x,
                      Eigen::Ref<Vec3> v) {
    const Real d = terrain.signed_distance(x, t) - gap;
    if (d >= 0 || !terrain.can_contact(x, t)) return false;
    const Vec3 n = terrain.normal(x, t);
    const Vec3 u = terrain.surface_velocity(x, t);
    x -= d * n;
    const Vec3 relative = v - u;
    const Real vn = relative.dot(n);
    if (vn >= 0) return true;
    const bool impact = -(v_before - u).dot(n) > c.resting_speed;
    const Real vn_new = impact ? -c.restitution * vn : 0.0;
    const Real dvn = vn_new - vn;
    Vec3 vt = relative - vn * n;
    const Real speed_t = vt.norm();
    if (speed_t <= c.static_friction * dvn) {
      const Vec3 slip = x - x_before - h * u;
      x -= slip - slip.dot(n) * n;
      vt.setZero();
    } else {
      const Real keep = 1.0 - c.friction * dvn / speed_t;
      x -= h * (1.0 - keep) * vt;
      vt *= keep;
    }
    v = u + vn_new * n + vt;
    return true;
  }
};

}  // namespace

const TerrainContactModel& coulomb_contact_model() {
  static const CoulombModel model;
  return model;
}

}  // namespace jelly
