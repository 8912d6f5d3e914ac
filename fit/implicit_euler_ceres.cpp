#include <jelly/fit/detail/implicit_euler_ceres.hpp>

#include <chrono>
#include <cmath>
#include <vector>

#include <ceres/ceres.h>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly {

namespace {

// r = sqrt(m) (x - y) / h for one particle; dr/dx = sqrt(m) / h I.
class InertiaResidual final : public ceres::SizedCostFunction<3, 3> {
 public:
  InertiaResidual(const double* y, const double* scale) : y_(y), scale_(scale) {}
  bool Evaluate(double const* const* x, double* r, double** jacobians) const override {
    const double s = *scale_;
    for (int c = 0; c < 3; ++c) r[c] = s * (x[0][c] - y_[c]);
    if (jacobians && jacobians[0]) {
      for (int i = 0; i < 9; ++i) jacobians[0][i] = 0;
      for (int c = 0; c < 3; ++c) jacobians[0][4 * c] = s;
    }
    return true;
  }

 private:
  const double* y_;      // this particle's y, owned by the integrator
  const double* scale_;  // sqrt(m) / h, owned by the integrator
};

// r = sqrt(ks) (|xa - xb| - l0); dr/dxa = sqrt(ks) d^T = -dr/dxb, d = (xa - xb) / |xa - xb|.
class SpringResidual final : public ceres::SizedCostFunction<1, 3, 3> {
 public:
  SpringResidual(const double* sqrt_ks, const double* rest) : sqrt_ks_(sqrt_ks), rest_(rest) {}
  bool Evaluate(double const* const* x, double* r, double** jacobians) const override {
    const Eigen::Map<const Vec3> xa(x[0]), xb(x[1]);
    const Vec3 delta = xa - xb;
    const double length = delta.norm();
    if (!(length > 0)) return false;
    r[0] = *sqrt_ks_ * (length - *rest_);
    const Vec3 g = *sqrt_ks_ / length * delta;
    if (jacobians && jacobians[0]) Vec3::Map(jacobians[0]) = g;
    if (jacobians && jacobians[1]) Vec3::Map(jacobians[1]) = -g;
    return true;
  }

 private:
  const double* sqrt_ks_;
  const double* rest_;
};

}  // namespace

struct ImplicitEulerCeres::Impl {
  // The problem is built once per spring topology; the cost functions read y, sqrt(m)/h,
  // sqrt(ks) and l0 from these arrays, which every step refreshes.
  std::unique_ptr<ceres::Problem> problem;
  std::vector<int> a, b;  // topology the problem was built for
  int particles = -1;
  VecX x;  // the parameter blocks: particle i at x[3i]
  VecX y;
  VecX scale;
  std::vector<double> sqrt_ks, rest;
  VecX f, f_springs;
  long iterations = 0;
  double seconds = 0;

  void build(const Model& model) {
    const Springs& s = model.springs;
    particles = model.num_particles();
    a = s.a;
    b = s.b;
    x.setZero(model.num_dofs());
    y.setZero(model.num_dofs());
    scale.setZero(particles);
    sqrt_ks.assign(s.size(), 0);
    rest.assign(s.size(), 0);
    problem = std::make_unique<ceres::Problem>();
    for (int i = 0; i < particles; ++i) {
      problem->AddResidualBlock(new InertiaResidual(y.data() + 3 * i, scale.data() + i), nullptr,
                                x.data() + 3 * i);
    }
    for (int j = 0; j < s.size(); ++j) {
      problem->AddResidualBlock(new SpringResidual(&sqrt_ks[j], &rest[j]), nullptr,
                                x.data() + 3 * s.a[j], x.data() + 3 * s.b[j]);
    }
  }
};

ImplicitEulerCeres::ImplicitEulerCeres() : impl_(std::make_unique<Impl>()) {}
ImplicitEulerCeres::~ImplicitEulerCeres() = default;

Statistics ImplicitEulerCeres::statistics() const {
  Statistics s = Integrator::statistics();
  s["ceres_iterations"] = static_cast<double>(impl_->iterations);
  s["ceres_seconds"] = impl_->seconds;
  return s;
}

StepResult ImplicitEulerCeres::do_step(const Dynamics& dynamics, State& state, Real h) {
  const Model& model = dynamics.model();
  const Springs& s = model.springs;
  Impl& m = *impl_;
  for (int j = 0; j < s.size(); ++j) {
    require(s.kd[j] == 0, "springs[" + std::to_string(j) + "].kd", s.kd[j],
            "0: implicit_euler_ceres handles undamped springs only");
  }
  if (m.particles != model.num_particles() || m.a != s.a || m.b != s.b) m.build(model);

  // f_ext = f(x_n, v_n) - f_springs(x_n): gravity and any force-level contact, explicit.
  const Eigen::Index n = model.num_dofs();
  ensure_size(m.f, n);
  ensure_size(m.f_springs, n);
  dynamics.forces(state.t + h, state.x, state.v, m.f);
  m.f_springs.setZero();
  add_spring_forces(model, state.x, state.v, m.f_springs);
  for (int i = 0; i < model.num_particles(); ++i) {
    const Real mass = model.mass[i];
    particle(m.y, i) = particle(state.x, i) + h * particle(state.v, i) +
                       (h * h / mass) * (particle(m.f, i) - particle(m.f_springs, i));
    m.scale[i] = std::sqrt(mass) / h;
  }
  for (int j = 0; j < s.size(); ++j) {
    m.sqrt_ks[j] = std::sqrt(s.ks[j]);
    m.rest[j] = s.rest_length[j];
  }
  m.x = state.x + h * state.v;  // the explicit predictor as the starting point

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-20;
  options.gradient_tolerance = 1e-20;
  options.parameter_tolerance = 1e-15;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  const auto start = std::chrono::steady_clock::now();
  ceres::Solve(options, m.problem.get(), &summary);
  m.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m.iterations += static_cast<long>(summary.iterations.size()) - 1;
  if (summary.termination_type != ceres::CONVERGENCE) {
    return StepResult::failure("implicit_euler_ceres: " + summary.message);
  }
  state.v = (m.x - state.x) / h;
  state.x = m.x;
  state.t += h;
  return StepResult::success();
}

std::unique_ptr<Integrator> make_implicit_euler_ceres() {
  return std::make_unique<ImplicitEulerCeres>();
}

std::unique_ptr<Integrator> make_fit_integrator(std::string_view name,
                                                const IntegratorOptions& options) {
  if (name == "implicit_euler_ceres") return make_implicit_euler_ceres();
  return make_integrator(name, options);
}

}  // namespace jelly
