#pragma once
// Springs from particles to points in space: pulls from outside the model (the viewer drags a
// particle with one). Each acts on one particle, so its Jacobian is diagonal and the implicit
// integrators add it to their matrix (an explicit treatment of a stiff pull at a large step
// would be unstable).
#include <vector>

#include <jelly/core/jacobian.hpp>
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

// The anchors' part of A = M - alpha D - beta K and of kw = K w, for a matrix `a` with the
// pattern of `jacobian`: per anchor K_pp = -k I and D_pp = -c I, so A_pp += (alpha c + beta k) I
// and (K w)_p -= k w_p. No allocation.
void add_anchor_system(const AnchorSprings& anchors, const SpringJacobian& jacobian, Real alpha,
                       Real beta, SparseMatrix& a, const VecX& w, VecX& kw);
// Adds the anchors' K and D (diagonal) to matrices with the pattern of `jacobian`.
void add_anchor_jacobians(const AnchorSprings& anchors, const SpringJacobian& jacobian,
                          SparseMatrix& k, SparseMatrix& d);

}  // namespace jelly
