#pragma once
// Springs from particles to points in space: pulls from outside the model (the viewer drags a
// particle with one). Each acts on one particle, so its Jacobian is diagonal and the implicit
// integrators add it to their matrix (core/detail/anchor_jacobian.hpp; an explicit treatment of
// a stiff pull at a large step would be unstable).
#include <vector>

#include <jelly/core/types.hpp>

namespace jelly {

struct AnchorSpring {
  int particle = 0;
  Vec3 target = Vec3::Zero();  // m
  Real stiffness = 0;          // k, N/m, >= 0
  Real damping = 0;            // c, N s/m, >= 0, on the particle's own velocity
};
using AnchorSprings = std::vector<AnchorSpring>;

// Throws InputError for a particle index outside [0, num_particles), a non-finite target or a
// negative or non-finite coefficient.
void validate_anchors(const AnchorSprings& anchors, int num_particles);

// f_p += -k (x_p - target) - c v_p for every anchor. No allocation.
void add_anchor_forces(const AnchorSprings& anchors, const VecX& x, const VecX& v, VecX& f);

}  // namespace jelly
