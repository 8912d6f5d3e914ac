#pragma once
// Backward Euler solved as a nonlinear least-squares problem with Ceres: an independent check of
// the Newton-based implicit_euler for undamped springs.
#include <memory>
#include <string_view>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

// One step minimises over x (the new positions)
//   sum_i m_i |x_i - y_i|^2 / h^2 + sum_springs ks (|x_a - x_b| - l0)^2,
//   y = x_n + h v_n + h^2 M^-1 f_ext,
// whose stationarity condition M (x - y) / h^2 = f_spring(x) is the backward Euler equation;
// then v = (x - x_n) / h. f_ext is every force but the springs (gravity, seed contact forces),
// taken at the start of the step. Springs must be undamped (kd = 0): a damper is not the
// gradient of an energy. Not in the solvers registry (fit is a higher layer): create it with
// make_implicit_euler_ceres() or make_fit_integrator("implicit_euler_ceres").
class ImplicitEulerCeres final : public Integrator {
 public:
  ImplicitEulerCeres();
  ~ImplicitEulerCeres() override;

  std::string_view name() const override { return "implicit_euler_ceres"; }
  int order() const override { return 1; }
  bool is_implicit() const override { return true; }
  // steps, plus ceres_iterations (total) and ceres_seconds.
  Statistics statistics() const override;

 protected:
  // Throws InputError if a spring has kd != 0. A Ceres failure is a returned failure.
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::unique_ptr<Integrator> make_implicit_euler_ceres();

// make_integrator(name, options) of the registry, plus "implicit_euler_ceres".
std::unique_ptr<Integrator> make_fit_integrator(std::string_view name,
                                                const IntegratorOptions& options = {});

}  // namespace jelly
