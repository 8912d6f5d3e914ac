#pragma once
// Spectral estimates of a mass-spring model at its rest configuration: matrix-free products with
// the stiffness and damping Jacobians K = df/dx and D = df/dv, and the spectral radii of M^-1 K and
// M^-1 D by Lanczos on the symmetric M^-1/2 (-K) M^-1/2 (and the same for D).
#include <jelly/core/model.hpp>

namespace jelly::bench {

// y = K v with K = df/dx at the rest positions (no geometric term there, every spring at its rest
// length): for a spring (a, b) with unit direction d, (K v)_a = -ks d d^T (v_a - v_b), and
// (K v)_b the opposite. y must have size 3N.
void stiffness_product(const Model& model, const VecX& v, VecX& y);
// y = D v with D = df/dv at the rest positions: the same with kd in place of ks.
void damping_product(const Model& model, const VecX& v, VecX& y);

struct SpectralEstimate {
  Real rho_k = 0;  // spectral radius of M^-1 K (1/s^2): the largest omega^2
  Real rho_d = 0;  // spectral radius of M^-1 D (1/s)
  int iterations_k = 0, iterations_d = 0;
};

// Largest eigenvalue of M^-1/2 (-A) M^-1/2 for A = K (damping = false) or D, by Lanczos with full
// reorthogonalisation from a fixed start vector, stopped when the Ritz value's residual is below
// tolerance times itself or after max_iterations (or the dimension). `iterations` gets the count.
Real spectral_radius(const Model& model, bool damping, int max_iterations = 300,
                     Real tolerance = 1e-10, int* iterations = nullptr);

SpectralEstimate estimate_spectrum(const Model& model);

}  // namespace jelly::bench
