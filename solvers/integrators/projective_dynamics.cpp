#include <jelly/solvers/integrators/detail/projective_dynamics.hpp>

#include <chrono>
#include <cmath>

#include <Eigen/Eigenvalues>

#include <jelly/core/detail/clock.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/contact/detail/position_contact.hpp>
#include <jelly/solvers/linear/detail/cholmod_solver.hpp>

namespace jelly {

namespace {

// Contact penalties in the factor, as multiples of the particle's diagonal entry of A: a
// sticking contact is (nearly) held in place by the global solve, a sliding one partly. The
// exact contact comes from the residual (position_contact.hpp); the penalties only make the
// iterations converge in contact (sync_penalties).
constexpr Real kStickPenalty = 1e3;
constexpr Real kSlidePenalty = 3;
// The first step measures the plain iteration's contraction with at least this many iterations.
constexpr int kRhoIterations = 8;
// Measured radii are kept below this (an acceleration for rho -> 1 overshoots).
constexpr Real kMaxRho = 0.999;

// A = M / h^2 + sum over springs of (ks + kd / h) (e_a - e_b) (e_a - e_b)^T: N x N, full storage.
SparseMatrix global_matrix(const Model& model, Real h) {
  const int n = model.num_particles();
  const Springs& s = model.springs;
  std::vector<Eigen::Triplet<Real, int>> entries;
  entries.reserve(n + 4 * static_cast<size_t>(s.size()));
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, model.mass[i] / (h * h));
  for (int k = 0; k < s.size(); ++k) {
    const Real w = s.ks[k] + s.kd[k] / h;
    const int a = s.a[k], b = s.b[k];
    entries.emplace_back(a, a, w);
    entries.emplace_back(b, b, w);
    entries.emplace_back(a, b, -w);
    entries.emplace_back(b, a, -w);
  }
  SparseMatrix a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

}  // namespace

ProjectiveDynamics::ProjectiveDynamics(ProjectiveDynamicsOptions options)
    : options_(std::move(options)), contact_(std::make_unique<PositionContact>()) {
  options_.validate();
  rho_ = options_.chebyshev_rho;
  residuals_.reserve(options_.iterations + 2);
  step_norms_.reserve(std::max(options_.iterations, kRhoIterations) + 1);
}

ProjectiveDynamics::~ProjectiveDynamics() = default;

std::vector<ToleranceMiss> ProjectiveDynamics::tolerance_misses() const {
  if (options_.tolerance == 0) return {};
  return {{"projective_dynamics: the residual stayed above integrator.options.tolerance = " +
               tolerance_text(options_.tolerance) +
               " after iterations = " + std::to_string(options_.iterations),
           not_converged_}};
}

Statistics ProjectiveDynamics::statistics() const {
  Statistics s = Integrator::statistics();
  s["symbolic_analyses"] = static_cast<double>(analyses_);
  s["factorizations"] = static_cast<double>(factorizations_);
  s["iterations"] = static_cast<double>(iterations_);
  s["factor_updates"] =
      static_cast<double>(rank_updates_ + (solver_ ? solver_->rank_updates() : 0));
  s["not_converged"] = static_cast<double>(not_converged_);
  s["factorization_seconds"] = factorization_seconds_;
  s["solve_seconds"] = solve_seconds_;
  if (options_.chebyshev) s["chebyshev_rho"] = rho_;
  if (contact_in_step())
    s["contact_restitution_limited"] =
        static_cast<double>(contact_->counters().restitution_limited);
  return s;
}

std::vector<Real> ProjectiveDynamics::internal_state() const {
  if (options_.chebyshev && options_.chebyshev_rho == 0 && rho_ > 0) return {rho_};
  return {};
}

void ProjectiveDynamics::restore_internal_state(const std::vector<Real>& data) {
  if (data.empty()) {
    rho_ = options_.chebyshev_rho;
    return;
  }
  require(data.size() == 1 && data[0] >= 0 && data[0] < 1, "integrator state (chebyshev_rho)",
          data[0], "a saved projective_dynamics state: one spectral radius in [0, 1)");
  if (options_.chebyshev && options_.chebyshev_rho == 0) rho_ = data[0];
}

StepResult ProjectiveDynamics::prepare(const Model& model, Real h) {
  const Springs& s = model.springs;
  const bool same_model = solver_ && mass_.size() == model.mass.size() && mass_ == model.mass &&
                          ks_ == s.ks && kd_ == s.kd && spring_a_ == s.a && spring_b_ == s.b;
  if (same_model && h == h_) return StepResult::success();
  const auto start = Clock::now();
  // Once per model and time step (allocates).
  a_ = global_matrix(model, h);
  if (!same_model) {
    CholmodOptions cholmod;
    cholmod.ordering = options_.ordering;
    if (solver_) rank_updates_ += solver_->rank_updates();
    solver_ = std::make_unique<CholmodSolver>(cholmod);
    const LinearResult r = solver_->analyze(a_);
    ++analyses_;
    if (!r.ok()) return StepResult::failure("projective_dynamics: " + r.message);
    mass_ = model.mass;
    ks_ = s.ks;
    kd_ = s.kd;
    spring_a_ = s.a;
    spring_b_ = s.b;
    const int n = model.num_particles();
    rhs_.setZero(n, 3);
    solution_.setZero(n, 3);
    for (VecX* v : {&x_, &x_prev_, &v_, &f_, &r_, &delta_}) v->setZero(3 * n);
  }
  h_ = 0;
  const LinearResult r = solver_->factorize(a_);
  ++factorizations_;
  factorization_seconds_ += seconds_since(start);
  if (!r.ok()) return StepResult::failure("projective_dynamics: " + r.message);
  h_ = h;
  diagonal_ = a_.diagonal();
  penalty_.assign(model.num_particles(), 0.0);  // the new factor holds no penalties
  if (anchor_weight_.size() != static_cast<size_t>(model.num_particles())) {
    anchor_weight_.assign(model.num_particles(), 0.0);
    anchored_.clear();
    pinned_.assign(model.num_particles(), 0);
    pinned_list_.clear();
  }
  penalized_list_.clear();
  return StepResult::success();
}

void ProjectiveDynamics::residual(const Dynamics& dynamics, const State& s0, Real h) {
  const Model& model = dynamics.model();
  const int n = model.num_particles();
  const Real inv_h = 1.0 / h;
  v_ = (x_ - s0.x) * inv_h;
  dynamics.forces(s0.t + h, x_, v_, f_);
  // r = f - M (v - v0) / h
  for (int i = 0; i < n; ++i) {
    const Real m = model.mass[i] * inv_h;
    for (int c = 0; c < 3; ++c)
      r_[3 * i + c] = f_[3 * i + c] - m * (v_[3 * i + c] - s0.v[3 * i + c]);
  }
  if (contact_active_) contact_->constrain_residual(x_, r_);
  for (int i : model.pins.particles) particle(r_, i).setZero();  // the pin takes it
}

void ProjectiveDynamics::place_pins(const Model& model, Real t) {
  const Pins& pins = model.pins;
  for (int k = 0; k < pins.size(); ++k) particle(x_, pins.particles[k]) = pins.position(k, t);
}

void ProjectiveDynamics::set_pins(const Pins& pins) {
  for (int i : pinned_list_) pinned_[i] = 0;
  pinned_list_ = pins.particles;  // (no allocation once the pins are the same)
  for (int i : pinned_list_) pinned_[i] = 1;
}

void ProjectiveDynamics::set_anchor_weights(const Dynamics& dynamics, const State& s, Real h) {
  for (int i : anchored_) anchor_weight_[i] = 0;
  anchored_.clear();
  const auto add = [&](int i, Real w) {
    if (!(w > 0)) return;
    if (anchor_weight_[i] == 0) anchored_.push_back(i);
    anchor_weight_[i] += w;
  };
  if (const AnchorSprings* anchors = dynamics.anchors(); anchors != nullptr) {
    for (const AnchorSpring& a : *anchors) add(a.particle, a.stiffness + a.damping / h);
  }
  dynamics.added_force_jacobians(s.t, s.x, s.v, jacobian_);
  for (const ForceJacobian::Block& b : jacobian_.blocks()) {
    if (b.i != b.j) continue;
    const Mat3 stiffness = -(b.dfdx + b.dfdv / h);
    const Real largest = Eigen::SelfAdjointEigenSolver<Mat3>(
                             0.5 * (stiffness + stiffness.transpose()), Eigen::EigenvaluesOnly)
                             .eigenvalues()[2];
    if (largest > 0) add(b.i, std::exp2(std::ceil(std::log2(largest))));
  }
}

StepResult ProjectiveDynamics::sync_penalties() {
  // What each particle should have in the factor beyond A: its anchor springs' k + c / h (their
  // Jacobian, as implicit_euler takes it), and a contact penalty: a sticking contact is held
  // (both along and across the surface); a sliding one must move along the surface, which the
  // isotropic penalty resists, but without any it lets the iterations diverge at stiff
  // contacts, so it gets a moderate one (docs/realtime.md); a free particle none.
  const auto wanted = [&](int i) {
    Real w = anchor_weight_[i];
    if (pinned_[i]) return w + kStickPenalty * diagonal_[i];
    if (!contact_active_) return w;
    switch (contact_->mode(i)) {
      case PositionContact::Mode::kStick:
      case PositionContact::Mode::kNew:
        return w + kStickPenalty * diagonal_[i];
      case PositionContact::Mode::kSlide:
        return w + kSlidePenalty * diagonal_[i];
      default:
        return w;
    }
  };
  const auto raise = [&](int i) {
    const Real change = wanted(i) - penalty_[i];
    if (change <= 0) return;
    if (penalty_[i] == 0) penalized_list_.push_back(i);
    rows_.push_back(i);
    values_.push_back(change);
    penalty_[i] += change;
  };
  for (int pass = 0; pass < 2; ++pass) {
    const bool add = pass == 1;
    rows_.clear();
    values_.clear();
    if (add) {
      if (contact_active_)
        for (int i : contact_->active()) raise(i);
      for (int i : anchored_) raise(i);
      for (int i : pinned_list_) raise(i);
    } else {  // downdates first, so that no particle is ever held twice
      size_t kept = 0;
      for (int i : penalized_list_) {
        const Real change = wanted(i) - penalty_[i];
        if (change < 0) {
          rows_.push_back(i);
          values_.push_back(-change);
          penalty_[i] += change;
          if (penalty_[i] <= 0) penalty_[i] = 0;
        }
        if (penalty_[i] > 0) penalized_list_[kept++] = i;
      }
      penalized_list_.resize(kept);
    }
    if (rows_.empty()) continue;
    const auto start = Clock::now();
    const LinearResult r = solver_->update_diagonal(rows_, values_, add);
    factorization_seconds_ += seconds_since(start);
    if (!r.ok()) return StepResult::failure("projective_dynamics: " + r.message);
  }
  return StepResult::success();
}

void ProjectiveDynamics::slide_correction(const Model& model, Real h) {
  shift_.setZero();
  if (!contact_active_ || contact_->active().empty() || !model.pins.empty()) return;
  Eigen::Matrix3d normals = Eigen::Matrix3d::Zero();
  for (int i : contact_->active()) {
    const PositionContact::Mode m = contact_->mode(i);
    if (m == PositionContact::Mode::kStick || m == PositionContact::Mode::kNew) return;
    if (m == PositionContact::Mode::kSlide)
      normals += contact_->normal(i) * contact_->normal(i).transpose();
  }
  // The directions no contact constrains: the null space of sum n n^T.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(normals);
  const Real largest = eigen.eigenvalues()[2];
  Eigen::Matrix3d free = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k) {
    if (eigen.eigenvalues()[k] <= 1e-9 * largest) {
      const Vec3 e = eigen.eigenvectors().col(k);
      free += e * e.transpose();
    }
  }
  if (largest <= 0 || free.isZero()) return;
  const int n = model.num_particles();
  Vec3 force = Vec3::Zero();
  for (int i = 0; i < n; ++i) force += particle(r_, i);
  shift_ = (h * h / model.mass.sum()) * (free * force);
  const Vec3 per_mass = shift_ / (h * h);
  for (int i = 0; i < n; ++i) particle(r_, i) -= model.mass[i] * per_mass;
}

StepResult ProjectiveDynamics::solve() {
  const Eigen::Index n = rhs_.rows();
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) rhs_(i, c) = r_[3 * i + c];
  const auto start = Clock::now();
  const LinearResult r = solver_->solve_columns(rhs_, solution_);
  solve_seconds_ += seconds_since(start);
  if (!r.ok()) return StepResult::failure("projective_dynamics: " + r.message);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) delta_[3 * i + c] = solution_(i, c);
  return StepResult::success();
}

LinearResult ProjectiveDynamics::solve_with_factor(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) {
  if (!solver_ || h_ == 0)
    return LinearResult::failure(LinearStatus::kInvalidInput, "projective_dynamics: no factor yet");
  return solver_->solve_columns(b, x);
}

StepResult ProjectiveDynamics::do_step(const Dynamics& dynamics, State& s, Real h) {
  const Model& model = dynamics.model();
  if (StepResult r = prepare(model, h); !r.ok) return r;
  const int n = model.num_particles();
  // The inertial prediction y = x0 + h v0 + h^2 g starts the iterations.
  for (int i = 0; i < n; ++i)
    particle(x_, i) = particle(s.x, i) + h * particle(s.v, i) + (h * h) * model.gravity;
  const Terrains* terrains = dynamics.terrains();
  terrains_seen_ = terrains != nullptr;
  contact_active_ = contact_in_step() && contact_->begin(model, *terrains, s, h, true);
  if (contact_active_) contact_->project(x_);
  place_pins(model, s.t + h);
  set_pins(model.pins);
  set_anchor_weights(dynamics, s, h);
  if (StepResult r = sync_penalties(); !r.ok) return r;

  const bool measure_rho = options_.chebyshev && rho_ == 0;
  const int budget =
      measure_rho ? std::max(options_.iterations, kRhoIterations) : options_.iterations;
  const bool accelerate = options_.chebyshev && !measure_rho;
  const Real gamma = options_.chebyshev_gamma;
  residuals_.clear();
  step_norms_.clear();
  Real omega = 1, first = 0;
  for (int k = 0;; ++k) {
    const bool last = k == budget;
    if (last && options_.tolerance == 0) break;
    // The contact set settles in the first half of the iterations; the second half converges
    // for it (docs/realtime.md).
    if (contact_active_) contact_->freeze(2 * k >= budget);
    residual(dynamics, s, h);
    const Real norm = r_.norm();
    if (!std::isfinite(norm))
      return StepResult::failure("projective_dynamics: the residual is not finite at t = " +
                                 to_text(s.t));
    residuals_.push_back(norm);
    if (k == 0) first = norm;
    if (options_.tolerance > 0 && norm <= options_.tolerance * first) break;
    if (last) {
      ++not_converged_;
      break;
    }
    if (contact_active_) {
      if (StepResult r = sync_penalties(); !r.ok) return r;
    }
    slide_correction(model, h);
    if (StepResult r = solve(); !r.ok) return r;
    for (int i = 0; i < n; ++i) particle(delta_, i) += shift_;
    ++iterations_;
    if (measure_rho) step_norms_.push_back(delta_.norm());
    // With contacts the recurrence starts once their set is frozen (an extrapolation across
    // changes of the set overshoots; measured: +35 % energy on the slope).
    const int from = (contact_active_ ? (budget + 1) / 2 : 0) + options_.chebyshev_delay;
    if (accelerate && k + 1 >= from) {
      // Wang 2015: x+ = omega (gamma (x^ - x) + x - x-) + x-, x^ = x + delta.
      omega = k + 1 == from ? 2 / (2 - rho_ * rho_) : 4 / (4 - rho_ * rho_ * omega);
      x_prev_ = omega * (gamma * delta_ + x_ - x_prev_) + x_prev_;
      x_.swap(x_prev_);
    } else {
      x_prev_ = x_;
      x_ += delta_;
    }
    if (contact_active_) contact_->project(x_);
    place_pins(model, s.t + h);
  }
  // (A first step whose prediction is already the answer, free fall, has nothing to measure.)
  if (measure_rho && first > 1e-9 * model.mass.sum() * model.gravity.norm()) {
    // Geometric mean of the step-norm ratios over the second half of the iterations.
    const int m = static_cast<int>(step_norms_.size());
    const int from = m / 2;
    if (m - from >= 2 && step_norms_[from] > 0 && step_norms_[m - 1] > 0) {
      const Real rate = std::pow(step_norms_[m - 1] / step_norms_[from], 1.0 / (m - 1 - from));
      if (std::isfinite(rate)) rho_ = std::clamp(rate, 0.0, kMaxRho);
    }
  }
  s.v = (x_ - s.x) / h;
  s.x = x_;
  s.t += h;
  if (contact_active_) contact_->finish(model, s, dynamics.threads());
  StepResult result = StepResult::success();
  result.contact = {contact_in_step(), false, contact_active_ ? contact_->count() : 0};
  return result;
}

}  // namespace jelly
