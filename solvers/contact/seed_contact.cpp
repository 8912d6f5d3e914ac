// The seed contact model: the seed report's rules once per step, for any integrator. After the
// step a particle within epsilon and approaching has its normal velocity reflected; during the
// next step its contact and friction forces act (carried contacts, ContactSolver::add_forces).
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/contact/detail/seed_rules.hpp>
#include <jelly/solvers/contact/detail/thickness.hpp>
#include <jelly/solvers/contact/terrain_contact_model.hpp>

namespace jelly {

namespace {

class SeedModel final : public TerrainContactModel {
 public:
  ContactModel kind() const override { return ContactModel::kSeed; }

  int resolve_after_step(const AfterStepContact& step, int begin, int end,
                         std::vector<CarriedContact>& carried) const override {
    int count = 0;
    thickness::for_ranges(step.model, begin, end, [&](int first, int last, Real gap) {
      for (int i = first; i < last; ++i) {
        Vec3 n;
        if (!seed_rules::reflect(step.terrain, step.params, step.model.mass[i], step.state.t, gap,
                                 particle(step.state.x, i), particle(step.state.v, i), n))
          continue;
        ++count;
        carried.push_back({i, n, step.params.friction});
      }
    });
    return count;
  }
};

}  // namespace

const TerrainContactModel& seed_contact_model() {
  static const SeedModel model;
  return model;
}

}  // namespace jelly
