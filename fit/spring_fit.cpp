#include <jelly/fit/spring_fit.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <sstream>

#include <random>
#include <stdexcept>

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <Eigen/Dense>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/fit/detail/implicit_euler_ceres.hpp>
#include <jelly/fit/detail/window_adjoint.hpp>
#include <jelly/fit/detail/window_start.hpp>
#include <jelly/solvers/adjoint/detail/projective_dynamics_adjoint.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly {

namespace {

constexpr std::array<SpringType, kSpringTypeCount> kTypes{SpringType::kStructural,
                                                          SpringType::kShear, SpringType::kBending};

// Frames [first, last] of the recording: replayed from frame `first`, compared at the others.
struct Window {
  int first = 0;
  int last = 0;
};

std::vector<Window> make_windows(const Trajectory& trajectory, Real length) {
  std::vector<Window> windows;
  const int last = trajectory.frames() - 1;
  const Real slack = 1e-9 * std::max<Real>(1, std::abs(trajectory.times[last]));
  int first = 0;
  while (first < last) {
    int end = first + 1;
    if (length == 0) {
      end = last;
    } else {
      while (end < last && trajectory.times[end + 1] - trajectory.times[first] <= length + slack)
        ++end;
    }
    windows.push_back({first, end});
    first = end;
  }
  return windows;
}

void set_parameter(Model& model, const FitParameter& p, Real value) {
  Springs& s = model.springs;
  std::vector<Real>& target = p.quantity == FitParameter::Quantity::kKs ? s.ks : s.kd;
  const auto [first, end] = p.spring_range(model);
  for (int j = first; j < end; ++j)
    if (p.applies_to(s.type[j])) target[j] = value;
}

// Replays one window with the model's coefficients and writes x_replay - x_recorded for each
// compared frame into `residuals`. Returns false if the integrator fails or the state blows up.
bool replay_window(const Trajectory& trajectory, const Model& model, const Window& w,
                   const State& start, double* residuals) {
  Simulator sim = window_simulator(trajectory, model, w.first, start);
  const Eigen::Index n = model.num_dofs();
  for (int k = w.first + 1; k <= w.last; ++k) {
    const long steps = std::lround((trajectory.times[k] - trajectory.times[k - 1]) / trajectory.dt);
    for (long i = 0; i < steps; ++i)
      if (!sim.step().ok) return false;
    if (!sim.state().x.allFinite()) return false;
    Eigen::Map<VecX>(residuals + (k - w.first - 1) * n, n) =
        sim.state().x - trajectory.positions[k];
  }
  return true;
}

bool replay_window(const Trajectory& trajectory, const Model& model, const Window& w,
                   double* residuals) {
  return replay_window(trajectory, model, w, trajectory.state(w.first), residuals);
}

// The residuals of one window as a function of the log-coefficients (parameter block 0) and,
// when the restart velocities are fitted, of the window's initial velocity (block 1).
class WindowResiduals {
 public:
  WindowResiduals(const Trajectory& trajectory, const std::vector<FitParameter>& free, Window w,
                  bool fitted_velocity, std::atomic<long>& replays)
      : trajectory_(&trajectory),
        free_(&free),
        window_(w),
        fitted_velocity_(fitted_velocity),
        replays_(&replays) {}

  bool operator()(double const* const* parameters, double* residuals) const {
    Model model = trajectory_->model;
    for (size_t p = 0; p < free_->size(); ++p)
      set_parameter(model, (*free_)[p], std::exp(parameters[0][p]));
    ++*replays_;
    State start = trajectory_->state(window_.first);
    if (fitted_velocity_) start.v = Eigen::Map<const VecX>(parameters[1], start.v.size());
    return replay_window(*trajectory_, model, window_, start, residuals);
  }

 private:
  const Trajectory* trajectory_;
  const std::vector<FitParameter>* free_;
  Window window_;
  bool fitted_velocity_;
  std::atomic<long>* replays_;
};

// Covariance of the log-coefficients when the recorded positions carry independent noise of
// variance s^2, which enters twice: in the frames compared (residual -e) and in the restart
// states of the windows (positions, and velocities by finite differences when none were
// recorded and they are not fitted), which every replayed frame of the window inherits.
// Linearised, r = r0 + A e and the least-squares estimate of all unknowns moves by
// -H^-1 J^T A e, H = J^T J. With G the rows of H^-1 that belong to the log-coefficients,
//   Cov = s^2 sum_e (G J^T a_e) (G J^T a_e)^T,   s^2 = |r|^2 / (trace(A A^T) - q),
// q the number of unknowns. The columns a_e that go through a restart are central differences
// of replays, with a step of the size of the noise.
struct RestartAwareCovariance {
  Eigen::MatrixXd meat;  // sum_e (G J^T a_e) (G J^T a_e)^T
  Real trace = 0;        // trace(A A^T)
  long replays = 0;
};

RestartAwareCovariance restart_aware_covariance(const Trajectory& trajectory, const Model& model,
                                                const std::vector<Window>& windows,
                                                const std::vector<VecX>& fitted_velocities,
                                                const Eigen::MatrixXd& jacobian,
                                                const Eigen::MatrixXd& gain, Real noise_scale) {
  const int n = trajectory.model.num_dofs();
  const int p_count = static_cast<int>(gain.rows());
  const bool fitted = !fitted_velocities.empty();
  std::vector<int> offset(windows.size() + 1, 0);
  for (size_t w = 0; w < windows.size(); ++w)
    offset[w + 1] = offset[w] + (windows[w].last - windows[w].first) * n;
  RestartAwareCovariance out;
  out.meat.setZero(p_count, p_count);
  Trajectory perturbed = trajectory;  // positions perturbed one coordinate at a time
  // Secant differences at the scale of the noise (the residual rms estimates it), not at
  // 1e-6 m: with contact, noise of that size moves particles across the surface, where the
  // projection responds non-smoothly; a tiny step sees one side only and gave standard
  // deviations that were too small on the slope (docs/fitting.md). On smooth data both agree.
  const Real delta = std::max<Real>(1e-6, noise_scale);
  VecX plus, minus;
  Eigen::VectorXd b(jacobian.cols());
  auto start_state = [&](size_t w) {
    State start = perturbed.state(windows[w].first);
    if (fitted) start.v = fitted_velocities[w];
    return start;
  };
  for (int k = 0; k < trajectory.frames(); ++k) {
    // Windows whose restart state depends on frame k.
    std::vector<size_t> restarts;
    for (size_t w = 0; w < windows.size(); ++w) {
      const int first = windows[w].first;
      const bool uses = trajectory.has_velocities() || fitted
                            ? first == k
                            : std::abs(std::clamp(first, 1, trajectory.frames() - 2) - k) <= 1;
      if (uses) restarts.push_back(w);
    }
    for (int c = 0; c < n; ++c) {
      b.setZero();
      for (size_t w = 0; w < windows.size(); ++w) {
        if (k > windows[w].first && k <= windows[w].last) {
          const int row = offset[w] + (k - windows[w].first - 1) * n + c;
          b -= jacobian.row(row).transpose();
          out.trace += 1;
        }
      }
      for (size_t w : restarts) {
        const int rows = offset[w + 1] - offset[w];
        plus.resize(rows);
        minus.resize(rows);
        perturbed.positions[k][c] = trajectory.positions[k][c] + delta;
        const bool ok_plus =
            replay_window(trajectory, model, windows[w], start_state(w), plus.data());
        perturbed.positions[k][c] = trajectory.positions[k][c] - delta;
        const bool ok_minus =
            replay_window(trajectory, model, windows[w], start_state(w), minus.data());
        perturbed.positions[k][c] = trajectory.positions[k][c];
        out.replays += 2;
        if (!ok_plus || !ok_minus) continue;
        const VecX column = (plus - minus) / (2 * delta);
        b += jacobian.middleRows(offset[w], rows).transpose() * column;
        out.trace += column.squaredNorm();
      }
      const Eigen::VectorXd shift = gain * b;
      out.meat += shift * shift.transpose();
    }
  }
  return out;
}

// ---- The exact-gradient path: the adjoint of implicit_euler per window. ----

// dL/d(log k) of each free coefficient from the adjoint's gradient per body and spring type.
void add_log_gradient(const Model& model, const std::vector<FitParameter>& free,
                      const double* log_k, const GradientResult& g, double* out) {
  for (size_t p = 0; p < free.size(); ++p) {
    const FitParameter& f = free[p];
    const std::vector<Real>& per = f.quantity == FitParameter::Quantity::kKs ? g.ks : g.kd;
    Real sum = 0;
    for (int b = 0; b < model.num_bodies(); ++b) {
      if (!f.body.empty() && model.bodies[b].name != f.body) continue;
      for (SpringType t : kTypes)
        if (f.applies_to(t))
          sum += per[static_cast<size_t>(kSpringTypeCount) * b + static_cast<int>(t)];
    }
    out[p] += std::exp(log_k[p]) * sum;
  }
}

Model model_with(const Trajectory& trajectory, const std::vector<FitParameter>& free,
                 const double* log_k) {
  Model model = trajectory.model;
  for (size_t p = 0; p < free.size(); ++p) set_parameter(model, free[p], std::exp(log_k[p]));
  return model;
}

// The cost 1/2 sum |x_replay - x_recorded|^2 over the windows and its gradient in the
// log-coefficients: one adjoint pass per window, the windows shared between up to `threads`
// threads (each takes the next window not yet taken; every window's result is kept and the sums
// are taken in window order, so the result is the same for any thread count). A refusal of the
// adjoint (what it does not differentiate, e.g. contact between bodies resolved after the step)
// is kept in `refused` (the first window's, in window order) and fails the evaluation.
class AdjointCost final : public ceres::FirstOrderFunction {
 public:
  AdjointCost(const Trajectory& trajectory, const std::vector<FitParameter>& free,
              const std::vector<Window>& windows, int threads)
      : trajectory_(&trajectory), free_(&free), windows_(&windows), threads_(threads) {}

  int NumParameters() const override { return static_cast<int>(free_->size()); }

  bool Evaluate(const double* log_k, double* cost, double* gradient) const override {
    const Model model = model_with(*trajectory_, *free_, log_k);
    const int count = static_cast<int>(windows_->size());
    std::vector<GradientResult> results(count);
    std::vector<std::string> refusals(count);
    std::vector<char> failed(count, 0);
    std::vector<std::exception_ptr> errors(count);  // anything else: rethrown below
    std::atomic<int> next{0};
    parallel::run(std::min(threads_, count), [&](int, int) {
      for (int k = next++; k < count; k = next++) {
        const Window& w = (*windows_)[k];
        const WindowFrameLoss loss = [&](int frame, const VecX& x, VecX& dl_dx) {
          dl_dx = x - trajectory_->positions[frame];
          return 0.5 * dl_dx.squaredNorm();
        };
        try {
          results[k] = fit_window_gradient(*trajectory_, model, w.first, w.last,
                                           trajectory_->state(w.first), loss);
        } catch (const InputError& e) {
          refusals[k] = e.what();
        } catch (const std::runtime_error&) {
          failed[k] = 1;  // a step or backward solve failed at these coefficients
        } catch (...) {
          errors[k] = std::current_exception();
        }
      }
    });
    for (const std::exception_ptr& e : errors)
      if (e) std::rethrow_exception(e);
    passes += count;
    *cost = 0;
    if (gradient != nullptr) std::fill(gradient, gradient + free_->size(), 0.0);
    for (int k = 0; k < count; ++k) {
      if (!refusals[k].empty()) {
        refused = refusals[k];
        return false;
      }
      if (failed[k] || !std::isfinite(results[k].loss)) return false;
      *cost += results[k].loss;
      if (gradient != nullptr) add_log_gradient(model, *free_, log_k, results[k], gradient);
    }
    return true;
  }

  mutable std::string refused;
  mutable long passes = 0;

 private:
  const Trajectory* trajectory_;
  const std::vector<FitParameter>* free_;
  const std::vector<Window>* windows_;
  int threads_;
};

// The weights of Trajectory::state's finite-difference velocity at frame k: v = sum_j w_j
// positions[c - 1 + j]; returns c - 1 (the first frame used).
int restart_velocity_weights(const Trajectory& trajectory, int k, Real w[3]) {
  const int last = trajectory.frames() - 1;
  const int c = std::clamp(k, 1, last - 1);
  const std::vector<Real>& times = trajectory.times;
  const Real t0 = times[c - 1], t1 = times[c], t2 = times[c + 1], t = times[k];
  w[0] = ((t - t1) + (t - t2)) / ((t0 - t1) * (t0 - t2));
  w[1] = ((t - t0) + (t - t2)) / ((t1 - t0) * (t1 - t2));
  w[2] = ((t - t0) + (t - t1)) / ((t2 - t0) * (t2 - t1));
  return c - 1;
}

// The number of random probes of the Hutchinson estimate of trace(D D^T) (D: the residuals'
// derivative with respect to the restart positions), which only the noise variance uses.
constexpr int kTraceProbes = 16;

// The restart-aware covariance of restart_aware_covariance, with the derivatives of each window
// with respect to its restart state from the adjoint instead of 2 x 3N replays per window:
//   J by central differences of replays (2 per coefficient and window),
//   J_w^T D_w (p x 3N) by p adjoint passes per window (loss = J_w column . residuals),
//   trace(D D^T) by kTraceProbes adjoint passes per window with Rademacher weights.
// Returns false with `why` when J^T J is singular.
bool adjoint_covariance(const Trajectory& trajectory, const std::vector<FitParameter>& free,
                        const std::vector<Window>& windows, const std::vector<double>& log_k,
                        Real relative_step, Eigen::MatrixXd& cov, Eigen::MatrixXd& h_inv,
                        Real& s2_independent, long& replays, long& passes, std::string& why) {
  const int n = trajectory.model.num_dofs();
  const int p_count = static_cast<int>(free.size());
  std::vector<int> offset(windows.size() + 1, 0);
  for (size_t w = 0; w < windows.size(); ++w)
    offset[w + 1] = offset[w] + (windows[w].last - windows[w].first) * n;
  const int rows = offset.back();
  // J, d(residuals)/d(log k), by central differences as Ceres' numeric path takes them.
  Eigen::MatrixXd jacobian(rows, p_count);
  VecX plus(rows), minus(rows), r0(rows);
  const auto residuals = [&](const std::vector<double>& at, VecX& out) {
    const Model model = model_with(trajectory, free, at.data());
    for (size_t w = 0; w < windows.size(); ++w) {
      ++replays;
      if (!replay_window(trajectory, model, windows[w], out.data() + offset[w])) return false;
    }
    return true;
  };
  if (!residuals(log_k, r0)) {
    why = "a replay failed at the fitted coefficients";
    return false;
  }
  for (int p = 0; p < p_count; ++p) {
    std::vector<double> at = log_k;
    const Real step = log_k[p] != 0 ? relative_step * std::abs(log_k[p]) : relative_step;
    at[p] = log_k[p] + step;
    const bool ok_plus = residuals(at, plus);
    at[p] = log_k[p] - step;
    if (!ok_plus || !residuals(at, minus)) {
      why = "a replay failed near the fitted coefficients";
      return false;
    }
    jacobian.col(p) = (plus - minus) / (2 * step);
  }
  const Eigen::MatrixXd h = jacobian.transpose() * jacobian;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(h);
  const Real largest = eigen.eigenvalues().maxCoeff(), smallest = eigen.eigenvalues().minCoeff();
  if (!(largest > 0) || !(smallest > 1e-14 * largest)) {
    why =
        "the Jacobian is rank deficient: some coefficient is not identifiable from this recording";
    return false;
  }
  h_inv = h.inverse();
  s2_independent = r0.squaredNorm() / (rows - p_count);
  const Model model = model_with(trajectory, free, log_k.data());
  const bool fd_velocities = !trajectory.has_velocities();
  // Per window: J_w^T D_w on the restart positions (p x 3N) and on the restart velocities.
  std::vector<Eigen::MatrixXd> jd_x(windows.size()), jd_v(windows.size());
  Real trace = rows;  // the compared frames' own noise: -I
  std::mt19937 random(20261128);
  std::uniform_int_distribution<int> coin(0, 1);
  VecX probe(rows);
  for (size_t w = 0; w < windows.size(); ++w) {
    const Window& win = windows[w];
    const State start = trajectory.state(win.first);
    const auto pass = [&](const double* weights) {
      const WindowFrameLoss loss = [&](int frame, const VecX& x, VecX& dl_dx) {
        dl_dx = Eigen::Map<const VecX>(weights + offset[w] + (frame - win.first - 1) * n, n);
        return dl_dx.dot(x);
      };
      ++passes;
      return fit_window_gradient(trajectory, model, win.first, win.last, start, loss);
    };
    jd_x[w].resize(p_count, n);
    jd_v[w].resize(p_count, n);
    for (int p = 0; p < p_count; ++p) {
      const GradientResult g = pass(jacobian.col(p).data());
      jd_x[w].row(p) = g.initial_position.transpose();
      jd_v[w].row(p) = g.initial_velocity.transpose();
    }
    // trace(D_w D_w^T) over the recorded positions the restart depends on, E |D_w^T y|^2.
    Real sum = 0;
    for (int q = 0; q < kTraceProbes; ++q) {
      for (int i = offset[w]; i < offset[w + 1]; ++i) probe[i] = coin(random) ? 1.0 : -1.0;
      const GradientResult g = pass(probe.data());
      if (!fd_velocities) {
        sum += g.initial_position.squaredNorm();
        continue;
      }
      Real weights[3];
      const int c0 = restart_velocity_weights(trajectory, win.first, weights);
      for (int j = 0; j < 3; ++j) {
        VecX column = weights[j] * g.initial_velocity;
        if (c0 + j == win.first) column += g.initial_position;
        sum += column.squaredNorm();
      }
    }
    trace += sum / kTraceProbes;
  }
  // sum over the recorded coordinates e of (H^-1 b_e)(H^-1 b_e)^T, b_e = J^T a_e.
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p_count, p_count);
  Eigen::VectorXd b(p_count);
  for (int k = 0; k < trajectory.frames(); ++k) {
    for (int c = 0; c < n; ++c) {
      b.setZero();
      for (size_t w = 0; w < windows.size(); ++w) {
        const Window& win = windows[w];
        if (k > win.first && k <= win.last)
          b -= jacobian.row(offset[w] + (k - win.first - 1) * n + c).transpose();
        if (!fd_velocities) {
          if (k == win.first) b += jd_x[w].col(c);
          continue;
        }
        Real weights[3];
        const int c0 = restart_velocity_weights(trajectory, win.first, weights);
        if (k == win.first) b += jd_x[w].col(c);
        if (k >= c0 && k < c0 + 3) b += weights[k - c0] * jd_v[w].col(c);
      }
      const Eigen::VectorXd shift = h_inv * b;
      meat += shift * shift.transpose();
    }
  }
  const Real s2 = r0.squaredNorm() / std::max<Real>(trace - p_count, 1);
  cov = s2 * meat;
  return true;
}

Real mean_coefficient(const Model& model, const FitParameter& p) {
  const Springs& s = model.springs;
  Real sum = 0;
  int count = 0;
  const auto [first, end] = p.spring_range(model);
  for (int j = first; j < end; ++j) {
    if (!p.applies_to(s.type[j])) continue;
    sum += p.quantity == FitParameter::Quantity::kKs ? s.ks[j] : s.kd[j];
    ++count;
  }
  return count > 0 ? sum / count : 0;
}

}  // namespace

std::string FitParameter::name() const {
  std::string n = body.empty() ? "" : body + ".";
  n += quantity == Quantity::kKs ? "ks" : "kd";
  if (type) n += "." + std::string(spring_type_name(*type));
  return n;
}

std::pair<int, int> FitParameter::spring_range(const Model& model) const {
  if (body.empty()) return {0, model.springs.size()};
  const Body* b = model.find_body(body);
  if (b == nullptr) {
    std::string known;
    for (const Body& other : model.bodies) known += (known.empty() ? "" : ", ") + other.name;
    throw InputError("free", name(), "a body of the recording: one of " + known);
  }
  return {b->first_spring, b->end_spring()};
}

std::vector<FitParameter> parse_free_parameters(std::string_view list) {
  std::vector<FitParameter> result;
  const std::string allowed =
      "a comma-separated list of ks, kd, ks.structural, ks.shear, ks.bending, kd.structural, "
      "kd.shear, kd.bending, each for every body or prefixed by a body's name (soft.ks), "
      "without overlaps";
  size_t start = 0;
  while (start <= list.size()) {
    const size_t comma = std::min(list.find(',', start), list.size());
    std::string_view item = list.substr(start, comma - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    FitParameter p;
    // "<body>.ks...": a first word other than ks and kd, or ks/kd followed by one that is not a
    // spring type (a body named "ks": "ks.ks"), names a body.
    const std::string_view first_word = item.substr(0, item.find('.'));
    const std::string_view after =
        first_word.size() < item.size() ? item.substr(first_word.size() + 1) : std::string_view();
    bool has_body = first_word != "ks" && first_word != "kd";
    if (!has_body && !after.empty()) {
      has_body = true;
      for (SpringType t : kTypes) has_body = has_body && after != spring_type_name(t);
    }
    if (has_body) {
      require(!first_word.empty() && !after.empty(), "free", std::string(list), allowed);
      p.body = std::string(first_word);
      item = after;
    }
    const std::string_view quantity = item.substr(0, item.find('.'));
    require(quantity == "ks" || quantity == "kd", "free", std::string(list), allowed);
    p.quantity = quantity == "ks" ? FitParameter::Quantity::kKs : FitParameter::Quantity::kKd;
    if (item.size() > 2) {
      bool known = false;
      for (SpringType t : kTypes) {
        if (item.substr(3) == spring_type_name(t) && item[2] == '.') {
          p.type = t;
          known = true;
        }
      }
      require(known, "free", std::string(list), allowed);
    }
    for (const FitParameter& q : result) {
      const bool overlap = q.quantity == p.quantity && (!q.type || !p.type || *q.type == *p.type) &&
                           (q.body.empty() || p.body.empty() || q.body == p.body);
      require(!overlap, "free", std::string(list), allowed);
    }
    result.push_back(p);
    start = comma + 1;
  }
  return result;
}

void FitOptions::validate() const {
  require(!free.empty(), "free", "(empty)", "at least one free coefficient");
  for (const auto& [name, value] : initial) {
    bool known = false;
    for (const FitParameter& p : free) known = known || p.name() == name;
    require(known, "initial." + name, value, "a value for one of the free parameters");
    require(std::isfinite(value) && value > 0, "initial." + name, value,
            "a finite value > 0 (the fit works on the logarithm)");
  }
  require(std::isfinite(window) && window >= 0, "window", window,
          "a finite length >= 0 s (0 = the whole recording)");
  require(max_iterations >= 1, "max_iterations", max_iterations, ">= 1");
  require(function_tolerance >= 0 && gradient_tolerance >= 0 && parameter_tolerance >= 0,
          "tolerance", std::min({function_tolerance, gradient_tolerance, parameter_tolerance}),
          ">= 0");
  require(relative_step > 0 && relative_step < 0.1, "relative_step", relative_step, "in (0, 0.1)");
  require(num_threads >= 1, "num_threads", num_threads, ">= 1");
}

const FittedParameter& FitResult::at(std::string_view name) const {
  for (const FittedParameter& p : parameters)
    if (p.name == name) return p;
  throw InputError("parameter", std::string(name), "one of the fitted parameters");
}

std::string FitResult::report() const {
  std::ostringstream out;
  out.precision(6);
  out << "fit of " << parameters.size() << " coefficient(s) over " << windows << " window(s), "
      << residuals << " residuals:\n";
  for (const FittedParameter& p : parameters) {
    out << "  " << p.name << " = " << p.value << " +- " << p.stddev << "  (start " << p.initial
        << "; +- " << p.stddev_independent << " if residuals were independent)\n";
  }
  out << "cost " << initial_cost << " -> " << final_cost << " m^2 (rms residual " << residual_rms
      << " m), " << iterations << " iterations, " << replays << " window replays, " << wall_seconds
      << " s (covariance " << covariance_seconds << " s), "
      << (converged ? "converged" : "NOT converged") << "\n";
  if (!restart_velocities.empty()) {
    out << "restart velocities fitted: " << restart_velocities.size() << " windows x "
        << restart_velocities.front().size() << " unknowns\n";
  }
  if (gradient_path == "adjoint") {
    out << "derivatives: adjoint (exact gradients of " << adjoint_integrator << ", "
        << adjoint_passes << " adjoint window passes; Ceres line search, BFGS)\n";
  } else {
    out << "derivatives: numeric (central differences of replays, Levenberg-Marquardt): "
        << gradient_reason << "\n";
  }
  out << "covariance: " << (covariance_ok ? "ok" : "failed: " + covariance_message) << "\n";
  out << "ceres: " << brief_report << "\n";
  return out.str();
}

Real replay_cost(const Trajectory& trajectory, Real window) {
  trajectory.validate();
  Real cost = 0;
  for (const Window& w : make_windows(trajectory, window)) {
    VecX r(static_cast<Eigen::Index>(w.last - w.first) * trajectory.model.num_dofs());
    if (!replay_window(trajectory, trajectory.model, w, r.data()))
      return std::numeric_limits<Real>::infinity();
    cost += 0.5 * r.squaredNorm();
  }
  return cost;
}

namespace {

// The fit's iteration limit, tolerances and progress output into a Ceres solver's options
// (ceres::Solver's or ceres::GradientProblemSolver's).
template <class SolverOptions>
void take_stopping_rules(const FitOptions& options, SolverOptions& solver) {
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.minimizer_progress_to_stdout = options.progress_to_stdout;
  solver.logging_type = options.progress_to_stdout ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
}

// The solver's summary and the fitted coefficients (exp of log_k) into `result`, their standard
// deviations not known yet (NaN). Summary: ceres::Solver's or ceres::GradientProblemSolver's.
template <class Summary>
void take_summary(const Summary& summary, const std::vector<double>& log_k, FitResult& result) {
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.termination = summary.message;
  result.brief_report = summary.BriefReport();
  result.residual_rms = std::sqrt(2 * summary.final_cost / result.residuals);
  for (size_t p = 0; p < log_k.size(); ++p) {
    result.parameters[p].value = std::exp(log_k[p]);
    result.parameters[p].stddev = std::numeric_limits<Real>::quiet_NaN();
    result.parameters[p].stddev_independent = std::numeric_limits<Real>::quiet_NaN();
  }
}

// Why the adjoint cannot take this fit before trying it ("" when it may).
std::string adjoint_refusal(const Trajectory& trajectory, const FitOptions& options) {
  if (!has_adjoint(trajectory.integrator))
    return "the recording's integrator is " + trajectory.integrator +
           " (the adjoint differentiates implicit_euler and projective_dynamics)";
  if (options.fit_restart_velocities)
    return "fit_restart_velocities (the covariance needs the velocities' full Jacobian)";
  return "";
}

// The exact-gradient path: Ceres' line search (BFGS) on the log-coefficients with the adjoint's
// gradient, and the restart-aware covariance from adjoint passes. Returns false, with
// result.gradient_reason saying why, when the numeric path must take the fit instead (throws
// InputError for that when options.gradients asks for the adjoint).
bool fit_with_adjoint(const Trajectory& trajectory, const FitOptions& options,
                      const std::vector<Window>& windows, std::vector<double>& log_k,
                      FitResult& result) {
  if (options.gradients == FitGradients::kNumeric) {
    result.gradient_reason = "asked for (gradients = numeric)";
    return false;
  }
  const auto refuse = [&](const std::string& why) {
    if (options.gradients == FitGradients::kAdjoint)
      throw InputError("gradients", "adjoint", "a fit the adjoint supports: " + why);
    result.gradient_reason = "the adjoint refused: " + why;
    return false;
  };
  if (std::string why = adjoint_refusal(trajectory, options); !why.empty()) return refuse(why);
  const std::vector<FitParameter>& free = options.free;
  const int p_count = static_cast<int>(free.size());
  auto* function = new AdjointCost(trajectory, free, windows, options.num_threads);
  ceres::GradientProblem problem(function);  // owns it
  // A probe at the start: what the adjoint refuses shows at once (anchors, wind, ...).
  {
    double cost = 0;
    std::vector<double> gradient(p_count);
    const bool ok = function->Evaluate(log_k.data(), &cost, gradient.data());
    if (!function->refused.empty()) return refuse(function->refused);
    if (!ok) return refuse("a replay failed at the starting values");
  }
  ceres::GradientProblemSolver::Options solver;
  // Few coefficients: dense BFGS builds the curvature from successive exact gradients.
  solver.line_search_direction_type = ceres::BFGS;
  take_stopping_rules(options, solver);
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(solver, problem, log_k.data(), &summary);
  if (!function->refused.empty()) return refuse(function->refused + " (during the fit)");
  result.gradient_path = "adjoint";
  result.adjoint_integrator = trajectory.integrator;
  result.adjoint_passes = function->passes;
  take_summary(summary, log_k, result);
  const auto covariance_start = std::chrono::steady_clock::now();
  if (!options.compute_covariance) {
    result.covariance_message = "not requested";
  } else if (result.residuals <= p_count) {
    result.covariance_message = "fewer residuals than unknowns";
  } else {
    Eigen::MatrixXd cov, h_inv;
    Real s2_independent = 0;
    long passes = 0;
    std::string why;
    if (adjoint_covariance(trajectory, free, windows, log_k, options.relative_step, cov, h_inv,
                           s2_independent, result.replays, passes, why)) {
      for (int p = 0; p < p_count; ++p) {
        FittedParameter& fp = result.parameters[p];
        fp.stddev = fp.value * std::sqrt(cov(p, p));
        fp.stddev_independent = fp.value * std::sqrt(s2_independent * h_inv(p, p));
      }
      result.covariance_ok = true;
    } else {
      result.covariance_message = why;
    }
    result.adjoint_passes += passes;
  }
  result.covariance_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - covariance_start).count();
  return true;
}

}  // namespace

FitGradients fit_gradients_from_name(std::string_view name, std::string_view field) {
  if (name == "auto") return FitGradients::kAuto;
  if (name == "adjoint") return FitGradients::kAdjoint;
  if (name == "numeric") return FitGradients::kNumeric;
  throw InputError(std::string(field), std::string(name), "one of auto, adjoint, numeric");
}

std::string_view fit_gradients_name(FitGradients gradients) {
  switch (gradients) {
    case FitGradients::kAdjoint:
      return "adjoint";
    case FitGradients::kNumeric:
      return "numeric";
    default:
      return "auto";
  }
}

FitResult fit_recording(const Trajectory& trajectory, const FitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  trajectory.validate();
  options.validate();
  const std::vector<FitParameter>& free = options.free;
  const int p_count = static_cast<int>(free.size());

  FitResult result;
  std::vector<double> log_k(p_count);
  for (int p = 0; p < p_count; ++p) {
    FittedParameter fitted;
    fitted.parameter = free[p];
    fitted.name = free[p].name();
    int springs = 0;
    const auto [first, end] = free[p].spring_range(trajectory.model);
    for (int j = first; j < end; ++j)
      springs += free[p].applies_to(trajectory.model.springs.type[j]);
    require(springs > 0, "free", fitted.name,
            free[p].body.empty() ? "a spring type the model has"
                                 : "a spring type body \"" + free[p].body + "\" has");
    const auto given = options.initial.find(fitted.name);
    fitted.initial = given != options.initial.end() ? given->second
                                                    : mean_coefficient(trajectory.model, free[p]);
    require(std::isfinite(fitted.initial) && fitted.initial > 0, "initial." + fitted.name,
            fitted.initial, "a finite start > 0 (the fit works on the logarithm)");
    log_k[p] = std::log(fitted.initial);
    result.parameters.push_back(fitted);
  }

  const std::vector<Window> windows = make_windows(trajectory, options.window);
  const int n = trajectory.model.num_dofs();
  for (const Window& w : windows) result.residuals += (w.last - w.first) * n;
  result.windows = static_cast<int>(windows.size());
  if (fit_with_adjoint(trajectory, options, windows, log_k, result)) {
    const auto end = std::chrono::steady_clock::now();
    result.wall_seconds = std::chrono::duration<double>(end - start).count();
    return result;
  }
  for (int p = 0; p < p_count; ++p) log_k[p] = std::log(result.parameters[p].initial);
  result.gradient_path = "numeric";
  std::atomic<long> replays{0};
  ceres::Problem problem;
  ceres::NumericDiffOptions diff;
  diff.relative_step_size = options.relative_step;
  // With fitted restart velocities every window has its own 3N velocity block, started from the
  // recorded (or finite-difference) velocity.
  const bool fit_velocities = options.fit_restart_velocities;
  std::vector<VecX> velocities;
  std::vector<double*> blocks{log_k.data()};
  if (fit_velocities) {
    velocities.reserve(windows.size());
    for (const Window& w : windows) velocities.push_back(trajectory.state(w.first).v);
    for (VecX& v : velocities) blocks.push_back(v.data());
  }
  for (size_t i = 0; i < windows.size(); ++i) {
    const Window& w = windows[i];
    auto* cost = new ceres::DynamicNumericDiffCostFunction<WindowResiduals, ceres::CENTRAL>(
        new WindowResiduals(trajectory, free, w, fit_velocities, replays), ceres::TAKE_OWNERSHIP,
        diff);
    cost->AddParameterBlock(p_count);
    if (fit_velocities) cost->AddParameterBlock(n);
    cost->SetNumResiduals((w.last - w.first) * n);
    if (fit_velocities) {
      problem.AddResidualBlock(cost, nullptr, log_k.data(), velocities[i].data());
    } else {
      problem.AddResidualBlock(cost, nullptr, log_k.data());
    }
  }
  const int unknowns = p_count + (fit_velocities ? n * result.windows : 0);

  ceres::Solver::Options solver;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // A few coefficients: dense QR. With a velocity block per window, each residual block touches
  // one of them, so the Schur complement onto the coefficients is exact and small.
  solver.linear_solver_type = fit_velocities ? ceres::DENSE_SCHUR : ceres::DENSE_QR;
  take_stopping_rules(options, solver);
  solver.num_threads = options.num_threads;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  take_summary(summary, log_k, result);

  const auto covariance_start = std::chrono::steady_clock::now();
  if (options.compute_covariance) {
    if (result.residuals <= unknowns) {
      result.covariance_message = "fewer residuals than unknowns";
    } else if (!(summary.initial_cost >= 0 && summary.final_cost >= 0)) {
      // Ceres' cost -1: the residuals could not be evaluated, so neither can their Jacobian
      // (ceres::Covariance on such a problem crashed).
      result.covariance_message = "the residuals could not be evaluated";
    } else {
      // Ceres returns the log-coefficients' block of (J^T J)^-1 (all unknowns): the covariance
      // for residuals that are independent with unit variance.
      ceres::Covariance::Options cov_options;
      cov_options.algorithm_type = ceres::DENSE_SVD;
      cov_options.num_threads = options.num_threads;
      ceres::Covariance covariance(cov_options);
      const std::vector<std::pair<const double*, const double*>> pairs{
          {log_k.data(), log_k.data()}};
      if (covariance.Compute(pairs, &problem)) {
        Eigen::MatrixXd h_inv(p_count, p_count);
        covariance.GetCovarianceBlock(log_k.data(), log_k.data(), h_inv.data());
        // The Jacobian at the solution, as Ceres differentiated it, columns in `blocks` order.
        ceres::CRSMatrix crs;
        ceres::Problem::EvaluateOptions evaluate;
        evaluate.parameter_blocks = blocks;
        problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs);
        Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
        for (int r = 0; r < crs.num_rows; ++r)
          for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i)
            jacobian(r, crs.cols[i]) = crs.values[i];
        // G: the coefficients' rows of H^-1 (H symmetric, so the solve of H G^T = E).
        Eigen::MatrixXd gain = h_inv;
        if (fit_velocities) {
          const Eigen::MatrixXd h = jacobian.transpose() * jacobian;
          gain = h.ldlt().solve(Eigen::MatrixXd::Identity(unknowns, p_count)).transpose();
        }
        Model fitted = trajectory.model;
        for (int p = 0; p < p_count; ++p) set_parameter(fitted, free[p], std::exp(log_k[p]));
        const RestartAwareCovariance restart = restart_aware_covariance(
            trajectory, fitted, windows, velocities, jacobian, gain, result.residual_rms);
        replays += restart.replays;
        const Real sum_squares = 2 * summary.final_cost;
        // Independent residuals: s^2 = |r|^2 / (m - q), Cov = s^2 (J^T J)^-1.
        const Real s2_independent = sum_squares / (result.residuals - unknowns);
        const Real s2 = sum_squares / std::max<Real>(restart.trace - unknowns, 1);
        const Eigen::MatrixXd cov = s2 * restart.meat;
        // Delta method: sd(k) = k sd(log k).
        for (int p = 0; p < p_count; ++p) {
          FittedParameter& fp = result.parameters[p];
          fp.stddev = fp.value * std::sqrt(cov(p, p));
          fp.stddev_independent = fp.value * std::sqrt(s2_independent * h_inv(p, p));
        }
        result.covariance_ok = true;
      } else {
        result.covariance_message =
            "the Jacobian is rank deficient: some coefficient is not identifiable from this "
            "recording";
      }
    }
  } else {
    result.covariance_message = "not requested";
  }
  result.restart_velocities = std::move(velocities);
  result.replays = replays.load();
  const auto end = std::chrono::steady_clock::now();
  result.covariance_seconds = std::chrono::duration<double>(end - covariance_start).count();
  result.wall_seconds = std::chrono::duration<double>(end - start).count();
  return result;
}

void apply_fit(Model& model, const FitResult& result) {
  for (const FittedParameter& p : result.parameters) set_parameter(model, p.parameter, p.value);
}

namespace {

void apply_fit(std::array<SpringCoefficients, kSpringTypeCount>& springs, const FitResult& result,
               std::string_view body) {
  for (const FittedParameter& p : result.parameters) {
    if (!p.parameter.body.empty() && p.parameter.body != body) continue;
    for (SpringType t : kTypes) {
      if (!p.parameter.applies_to(t)) continue;
      SpringCoefficients& c = springs[static_cast<int>(t)];
      (p.parameter.quantity == FitParameter::Quantity::kKs ? c.ks : c.kd) = p.value;
    }
  }
}

}  // namespace

void apply_fit(Material& material, const FitResult& result, std::string_view body) {
  apply_fit(material.springs, result, body);
}

void apply_fit(CubeSpec& spec, const FitResult& result) { apply_fit(spec.springs, result, ""); }

}  // namespace jelly
