#include <jelly/solvers/dynamics.hpp>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>

namespace jelly {

Dynamics::Dynamics(const Model& model, const ContactSolver& contacts, const Terrains* terrains,
                   const SpringBands* bands, const AnchorSprings* anchors, int threads,
                   BodyContact* body_contact, const ForceList* extra_forces)
    : model_(&model),
      contacts_(&contacts),
      terrains_(terrains),
      bands_(bands),
      anchors_(anchors != nullptr && !anchors->empty() ? anchors : nullptr),
      threads_(threads > 1 ? threads : 1),
      body_contact_(body_contact),
      forces_(extra_forces != nullptr && !extra_forces->empty() ? extra_forces : nullptr),
      in_evaluation_contact_(terrains != nullptr &&
                             ContactSolver::has_in_evaluation_contact(*terrains)) {}

void Dynamics::forces(Real t, const VecX& x, const VecX& v, VecX& f) const {
  ++evaluations_;
  if (bands_)
    bands_->compute_forces(*model_, x, v, f, threads_);
  else
    compute_forces(*model_, x, v, f);
  if (anchors_) add_anchor_forces(*anchors_, x, v, f);
  add_applied_forces(t, x, v, f);
  contacts_->add_forces(v, f);
}

void Dynamics::add_applied_forces(Real t, const VecX& x, const VecX& v, VecX& f) const {
  if (!model_->external_forces.empty())
    add_external_forces(model_->external_forces, model_->mass, t, v, f);
  if (forces_)
    for (const std::shared_ptr<Force>& force : *forces_) force->add_forces(t, x, v, f);
}

void Dynamics::added_force_jacobians(Real t, const VecX& x, const VecX& v,
                                     ForceJacobian& out) const {
  out.clear();
  if (forces_ == nullptr) return;
  const int n = model_->num_particles();
  for (const std::shared_ptr<Force>& force : *forces_) {
    if (!force->has_jacobian()) continue;
    const std::size_t before = out.blocks().size();
    force->add_jacobian(t, x, v, out);
    for (std::size_t k = before; k < out.blocks().size(); ++k) {
      const ForceJacobian::Block& b = out.blocks()[k];
      if (b.i < 0 || b.i >= n || b.j < 0 || b.j >= n || !b.dfdx.allFinite() ||
          !b.dfdv.allFinite()) {
        out.validate(n, force->name());  // throws, naming the block
      }
    }
  }
}

namespace {
// a = M^-1 f in place, then the pinned particles' path accelerations.
void finish_acceleration(const Model& model, int threads, Real t, VecX& a) {
  divide_by_masses(model, a, threads);
  if (!model.pins.empty()) model.pins.apply_acceleration(t, a);
}
}  // namespace

bool Dynamics::springs_and_seed_contacts_only() const {
  return bands_ != nullptr && anchors_ == nullptr && forces_ == nullptr &&
         model_->external_forces.empty();
}

namespace {
// The seed contact forces, added by each thread of the force loop to its own particles.
class SeedContactTerms final : public SpringBands::RangeTerms {
 public:
  SeedContactTerms(const ContactSolver& contacts, const VecX& v) : contacts_(contacts), v_(v) {}
  void add(int begin, int end, VecX& f) const override { contacts_.add_forces(v_, f, begin, end); }

 private:
  const ContactSolver& contacts_;
  const VecX& v_;
};
}  // namespace

void Dynamics::acceleration(Real t, const VecX& x, const VecX& v, VecX& a) const {
  if (springs_and_seed_contacts_only()) {
    // Gravity, springs and seed contact forces: the force loop's threads add the contact terms
    // and divide by the masses as they write (the same bits as forces() and the division).
    ++evaluations_;
    const SeedContactTerms terms(*contacts_, v);
    bands_->compute_accelerations(*model_, x, v, a, threads_,
                                  contacts_->seed_contacts().empty() ? nullptr : &terms);
    if (!model_->pins.empty()) model_->pins.apply_acceleration(t, a);
    return;
  }
  forces(t, x, v, a);
  finish_acceleration(*model_, threads_, t, a);
}

void Dynamics::stage_acceleration(Real t, const VecX& x, VecX& v, VecX& a) const {
  if (!in_evaluation_contact_) {
    acceleration(t, x, v, a);
    return;
  }
  forces(t, x, v, a);
  ContactSolver::apply_in_evaluation(*model_, *terrains_, t, x, v, a);
  finish_acceleration(*model_, threads_, t, a);
}

}  // namespace jelly
