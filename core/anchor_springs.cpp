#include <jelly/core/force.hpp>

#include <cmath>

#include <jelly/core/detail/anchor_jacobian.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

void validate_anchors(const AnchorSprings& anchors, int num_particles) {
  for (const AnchorSpring& s : anchors) {
    require(s.particle >= 0 && s.particle < num_particles, "anchor.particle", s.particle,
            "a particle index in [0, N)");
    require(s.target.allFinite(), "anchor.target", s.target.transpose(), "a finite point");
    require(std::isfinite(s.stiffness) && s.stiffness >= 0, "anchor.stiffness", s.stiffness,
            "a finite stiffness >= 0 N/m");
    require(std::isfinite(s.damping) && s.damping >= 0, "anchor.damping", s.damping,
            "a finite damping >= 0 N s/m");
  }
}

void add_anchor_forces(const AnchorSprings& anchors, const VecX& x, const VecX& v, VecX& f) {
  for (const AnchorSpring& s : anchors) {
    const int p = 3 * s.particle;
    f.segment<3>(p) -= s.stiffness * (x.segment<3>(p) - s.target) + s.damping * v.segment<3>(p);
  }
}

void add_anchor_system(const AnchorSprings& anchors, const SpringJacobian& jacobian, Real alpha,
                       Real beta, SparseMatrix& a, const VecX& w, VecX& kw) {
  for (const AnchorSpring& s : anchors) {
    const Real diagonal = alpha * s.damping + beta * s.stiffness;
    for (int c = 0; c < 3; ++c) jacobian.add_to_diagonal(a, 3 * s.particle + c, diagonal);
    kw.segment<3>(3 * s.particle) -= s.stiffness * w.segment<3>(3 * s.particle);
  }
}

void add_anchor_jacobians(const AnchorSprings& anchors, const SpringJacobian& jacobian,
                          SparseMatrix& k, SparseMatrix& d) {
  for (const AnchorSpring& s : anchors) {
    for (int c = 0; c < 3; ++c) {
      jacobian.add_to_diagonal(k, 3 * s.particle + c, -s.stiffness);
      jacobian.add_to_diagonal(d, 3 * s.particle + c, -s.damping);
    }
  }
}

}  // namespace jelly
