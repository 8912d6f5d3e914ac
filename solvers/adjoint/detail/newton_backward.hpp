#pragma once
// The backward solve of a converged Newton step of implicit_euler whose forward ran on the
// matrix-free system (docs/gradients.md, "Newton's backward solve"): F^T mu = b with F the exact
// Jacobian J = M - h D - h^2 K at the last iterate (x1, v1), filtered by the step's constraints
// as the forward filtered its system. J is the forward's own band system without the
// definiteness fix (its symmetric part) plus the dampers' non-symmetric term -kd / L u (P w)^T of
// each spring, kept as two vectors per spring; J^T is not symmetric, so the solve is BiCGSTAB,
// preconditioned with the forward CG's kind of preconditioner: block Jacobi (here the inverses of
// F^T's own diagonal blocks).
#include <vector>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class MatrixFreeNewtonBackward {
 public:
  // For `model`'s springs (its bands dense); single precision bands as the forward's matrix-free
  // system takes them for loose tolerances.
  MatrixFreeNewtonBackward(const Model& model, bool single_precision);

  // J at (x1, v1) for a step of size h. Returns false when a spring has collapsed.
  bool assemble(const Model& model, const VecX& x1, const VecX& v1, Real h, int threads);
  // J_pp += value I (the wind's drag). Call after assemble.
  void add_diagonal(int particle, Real value) { band_.add_diagonal(particle, value); }

  // Solves F^T mu = b to |b - F^T mu| <= tolerance |b| from the guess in mu, with `filter` the
  // step's constraints (input and output filter, as the forward's products; empty: none).
  LinearResult solve(const VecX& b, VecX& mu, const ProductFilter& filter, Real tolerance,
                     int max_iterations, int threads);
  // y = J^T p (unfiltered).
  void multiply_transposed(const VecX& p, VecX& y, int threads) const;

 private:
  // y = F^T p with the filter.
  void apply(const VecX& p, VecX& y, int threads) const;
  // z = P r (the block inverses).
  void precondition(const VecX& r, VecX& z) const;
  // y += N^T p, N the dampers' non-symmetric part of J.
  void add_damper_transposed(const VecX& p, VecX& y) const;

  SpringBands bands_;
  BandSystem band_;
  int num_particles_ = 0;
  std::vector<int> ends_;        // [2 per spring]: a, b
  std::vector<Real> terms_;      // [6 per spring]: u, then q = h^2 kd / L (P w)
  std::vector<Real> inverse_;    // [9 per particle]: row-major inverses of F^T's diagonal blocks
  ProductFilter filter_;         // of the current solve
  mutable VecX filtered_input_;  // S p
  VecX r_, r0_, p_, v_, s_, t_, y_, z_;
  mutable VecX scratch_;
};

}  // namespace jelly
