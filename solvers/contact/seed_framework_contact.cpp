// The seed_framework contact model: the seed report's rules where the course framework applied
// them, inside every force evaluation on that evaluation's own state (the explicit integrators
// only: a reflection inside an implicit solve's right-hand side is not a function of the state
// it iterates on).
#include <jelly/solvers/contact/detail/seed_rules.hpp>
#include <jelly/solvers/contact/detail/thickness.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>

namespace jelly {

namespace {

class SeedFrameworkModel final : public TerrainContactModel {
 public:
  ContactModel kind() const override { return ContactModel::kSeedFramework; }
  bool acts_in_evaluation() const override { return true; }

  // Nothing after the step: the next step's first force evaluation handles the particles
  // counted here (within epsilon and approaching).
  int resolve_after_step(const AfterStepContact& step, int begin, int end,
                         std::vector<CarriedContact>& /*carried*/) const override {
    int count = 0;
    thickness::for_ranges(step.model, begin, end, [&](int first, int last, Real gap) {
      for (int i = first; i < last; ++i) {
        Vec3 n, u;
        count += seed_rules::touches(step.terrain, step.params, step.state.t, gap,
                                     particle(step.state.x, i), particle(step.state.v, i), n, u);
      }
    });
    return count;
  }

  // For each particle within epsilon and approaching, v is reflected in place and, if f then
  // pushes it into the surface, the contact force -(f.n) n and the friction -mu N v_t
  // (N = -(f.n)) are added to f.
  void apply_in_evaluation(const Model& model, const Terrain& terrain, Real t, const VecX& x,
                           VecX& v, VecX& f) const override {
    const ContactParams& c = terrain.contact();
    thickness::for_ranges(model, 0, model.num_particles(), [&](int first, int last, Real gap) {
      for (int i = first; i < last; ++i) {
        auto vi = particle(v, i);
        Vec3 n;
        if (!seed_rules::reflect(terrain, c, model.mass[i], t, gap, particle(x, i), vi, n))
          continue;
        auto fi = particle(f, i);
        const Real fn = fi.dot(n);
        if (fn >= 0) continue;
        // The tangential velocity is the one before the reflection (which keeps it).
        const Vec3 vt = vi - vi.dot(n) * n;
        fi += -fn * n + c.friction * fn * vt;
      }
    });
  }
};

}  // namespace

const TerrainContactModel& seed_framework_contact_model() {
  static const SeedFrameworkModel model;
  return model;
}

}  // namespace jelly
