#include <jelly/solvers/dynamics.hpp>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/forces.hpp>

namespace jelly {

void Dynamics::forces(Real t, const VecX& x, const VecX& v, VecX& f) const {
  ++evaluations_;
  if (bands_)
    bands_->compute_forces(*model_, x, v, f, threads_);
  else
    compute_forces(*model_, x, v, f);
  if (anchors_) add_anchor_forces(*anchors_, x, v, f);
  if (!model_->external_forces.empty()) {
    add_external_forces(model_->external_forces, model_->mass, t, v, f);
  }
  contacts_->add_forces(v, f);
}

namespace {
// Particles per thread below which another thread costs more than it saves (the forces' own
// loop split the particles alike: each thread finishes what it summed).
constexpr long kMinParticlesPerThread = 1024;

// a = M^-1 f in place, then the pinned particles' path accelerations.
void finish_acceleration(const Model& model, int threads, Real t, VecX& a) {
  const Real* m = model.mass.data();
  Real* pa = a.data();
  parallel::for_ranges(
      threads, model.num_particles(),
      [&](long begin, long end) {
        for (long i = begin; i < end; ++i) {
          const Real inv = 1.0 / m[i];
          pa[3 * i] *= inv;
          pa[3 * i + 1] *= inv;
          pa[3 * i + 2] *= inv;
        }
      },
      kMinParticlesPerThread);
  if (!model.pins.empty()) model.pins.apply_acceleration(t, a);
}
}  // namespace

bool Dynamics::springs_only() const {
  return bands_ != nullptr && anchors_ == nullptr && model_->external_forces.empty() &&
         contacts_->seed_contacts().empty();
}

void Dynamics::acceleration(Real t, const VecX& x, const VecX& v, VecX& a) const {
  if (springs_only()) {
    // Gravity and springs only: the force loop divides by the masses as it writes (same bits).
    ++evaluations_;
    bands_->compute_accelerations(*model_, x, v, a, threads_);
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
