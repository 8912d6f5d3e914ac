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

void Dynamics::acceleration(Real t, const VecX& x, const VecX& v, VecX& a) const {
  forces(t, x, v, a);
  const Real* m = model_->mass.data();
  Real* pa = a.data();
  parallel::for_ranges(threads_, model_->num_particles(), [&](long begin, long end) {
    for (long i = begin; i < end; ++i) {
      const Real inv = 1.0 / m[i];
      pa[3 * i] *= inv;
      pa[3 * i + 1] *= inv;
      pa[3 * i + 2] *= inv;
    }
  });
  if (!model_->pins.empty()) model_->pins.apply_acceleration(t, a);
}

}  // namespace jelly
