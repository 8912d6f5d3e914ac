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
// a = M^-1 f in place, then the pinned particles' path accelerations.
void finish_acceleration(const Model& model, int threads, Real t, VecX& a) {
  const Real* m = model.mass.data();
  Real* pa = a.data();
  parallel::for_ranges(threads, model.num_particles(), [&](long begin, long end) {
    for (long i = begin; i < end; ++i) {
      const Real inv = 1.0 / m[i];
      pa[3 * i] *= inv;
      pa[3 * i + 1] *= inv;
      pa[3 * i + 2] *= inv;
    }
  });
  if (!model.pins.empty()) model.pins.apply_acceleration(t, a);
}
}  // namespace

void Dynamics::acceleration(Real t, const VecX& x, const VecX& v, VecX& a) const {
  forces(t, x, v, a);
  finish_acceleration(*model_, threads_, t, a);
}

void Dynamics::stage_acceleration(Real t, const VecX& x, VecX& v, VecX& a) const {
  forces(t, x, v, a);
  if (in_evaluation_contact_) ContactSolver::apply_in_evaluation(*model_, *terrains_, t, x, v, a);
  finish_acceleration(*model_, threads_, t, a);
}

}  // namespace jelly
