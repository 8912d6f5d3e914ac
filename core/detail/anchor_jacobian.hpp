#pragma once
// The anchor springs' (diagonal) Jacobians in the matrices of the implicit integrators.
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/force.hpp>

namespace jelly {

// The anchors' part of A = M - alpha D - beta K and of kw = K w, for a matrix `a` with the
// pattern of `jacobian`: per anchor K_pp = -k I and D_pp = -c I, so A_pp += (alpha c + beta k) I
// and (K w)_p -= k w_p. No allocation.
void add_anchor_system(const AnchorSprings& anchors, const SpringJacobian& jacobian, Real alpha,
                       Real beta, SparseMatrix& a, const VecX& w, VecX& kw);
// Adds the anchors' K and D (diagonal) to matrices with the pattern of `jacobian`.
void add_anchor_jacobians(const AnchorSprings& anchors, const SpringJacobian& jacobian,
                          SparseMatrix& k, SparseMatrix& d);

}  // namespace jelly
