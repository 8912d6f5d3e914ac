#pragma once
// Each integrator's linear stability on the damped test oscillator x'' = -w^2 x - c w^2 x' (a mode
// of M^-1 K with proportional damping D = c K), and the time step it predicts for a jelly whose
// stiffness spectrum is [0, rho]. The amplification matrix is measured by one step of the
// registered integrator itself on an equivalent two-particle spring, so any integrator in the
// registry gets a prediction; for the explicit methods it equals the stability polynomials
// (explicit Euler 1 + z, midpoint 1 + z + z^2/2, RK4 sum z^k/k!).
#include <string>

#include <Eigen/Core>

#include <jelly/core/types.hpp>

namespace jelly::bench {

// The 2x2 map (s, u) -> (s', u') of one step h of `integrator` on s'' = -w2 s - c w2 s', measured
// on two particles of mass 2 joined by a spring of ks = w2, kd = c w2 (rest length 1000, motion
// along the spring, where the spring force is exactly linear).
Eigen::Matrix2d amplification_matrix(const std::string& integrator, Real h, Real w2, Real c);

// Spectral radius of the amplification matrix.
Real amplification(const std::string& integrator, Real h, Real w2, Real c);

// The largest h (relative precision 1e-4) such that every mode with w^2 in [0, rho] (sampled
// geometrically from 1e-4 rho, 400 samples) has amplification <= 1 + 1e-9 (+ 1e-12 / h for
// implicit methods: the rounding of position-based velocities): the first boundary
// met when h grows from h_min. Returns h_cap when no instability is found below it, and 0 when
// h_min is already unstable.
Real predicted_max_dt(const std::string& integrator, Real rho, Real c, Real h_cap,
                      Real h_min = 1e-7);

// Whether `integrator` is adaptive (Integrator::is_adaptive(): its accuracy is set by a
// tolerance, and the scene's dt is only its contact-check interval).
bool is_adaptive_integrator(const std::string& integrator);

}  // namespace jelly::bench
