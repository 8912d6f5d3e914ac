#include <jelly/solvers/integrators/detail/matrix_free_system.hpp>

#include <jelly/core/detail/clock.hpp>
#include <jelly/solvers/contact/detail/implicit_contact.hpp>

namespace jelly {

namespace {

// At cg_tolerance at or above this the system keeps its two coefficients per spring in single
// precision (BandSystem): A is then exact to 6e-8 relative per spring, 1/16 of this, and the
// products read half the bytes (docs/implicit.md, "Matrix-free CG on lattices").
constexpr Real kSingleCoefficientsTolerance = 1e-6;

// Multigrid: the coarse operators (Galerkin products, many fine products' worth of work) are
// rebuilt every this many assemblies, and sooner when the contacts' set changes, when dt
// changes, or when a solve needs more than twice the iterations of the first solve with them
// (docs/implicit.md, "Multigrid on lattices"). Whatever coarse operators it holds, the V-cycle
// is symmetric positive definite.
constexpr int kMultigridMaxAge = 5;

}  // namespace

MatrixFreeSystem::MatrixFreeSystem(const ImplicitEulerOptions& options, SystemTimes& times)
    : options_(options), times_(times) {}

void MatrixFreeSystem::build(const Model& model, const SpringBands& bands) {
  band_.emplace(bands, model.num_particles(),
                options_.cg_tolerance >= kSingleCoefficientsTolerance);
  az_.setZero(model.num_dofs());
  use_multigrid_ = false;
  coarse_stale_ = true;
  if (options_.cg_preconditioner == CgPreconditionerKind::kMultigrid)
    use_multigrid_ = multigrid_.build(model, bands);
}

void MatrixFreeSystem::release() {
  band_.reset();
  use_multigrid_ = false;
}

std::string_view MatrixFreeSystem::name() const {
  return use_multigrid_ ? "cg_multigrid_matrix_free" : "cg_jacobi_matrix_free";
}

StepResult MatrixFreeSystem::collect_force_jacobians(const Dynamics& dynamics, const VecX& x,
                                                     const VecX& v, Real t) {
  dynamics.added_force_jacobians(t, x, v, force_jacobian_);
  return StepResult::success();
}

bool MatrixFreeSystem::assemble(const Dynamics& dynamics, const VecX& x, const VecX& v, Real h,
                                VecX& kw) {
  // A collapsed spring (its direction from the rest positions) cannot be held in the bands.
  if (!band_->assemble(dynamics.model(), x, v, options_.definiteness, h, h * h, v, kw, threads_))
    return false;
  ++coarse_age_;
  if (dynamics.anchors() != nullptr) {
    for (const AnchorSpring& anchor : *dynamics.anchors()) {
      band_->add_diagonal(anchor.particle, h * anchor.damping + h * h * anchor.stiffness);
      kw.segment<3>(3 * anchor.particle) -= anchor.stiffness * v.segment<3>(3 * anchor.particle);
    }
  }
  // The added forces' Jacobians, their symmetric part S = (J + J^T) / 2 as the assembled
  // system takes it: A -= h S_D + h^2 S_K, kw += S_K v.
  band_->set_extra_blocks(force_jacobian_, h, h * h);
  for (const ForceJacobian::Block& b : force_jacobian_.blocks()) {
    kw.segment<3>(3 * b.i) += 0.5 * b.dfdx * v.segment<3>(3 * b.j);
    kw.segment<3>(3 * b.j) += 0.5 * b.dfdx.transpose() * v.segment<3>(3 * b.i);
  }
  return true;
}

void MatrixFreeSystem::constrain(ImplicitContact& contacts, const VecX& b, bool prescribe,
                                 VecX& rhs, VecX& z, VecX& guess) {
  if (contacts.constrain_rhs(b, prescribe, nullptr, rhs, z, guess)) {
    band_->multiply(z, az_, threads_);
  } else {
    az_.setZero();
  }
  contacts.constrain_rhs(b, prescribe, &az_, rhs, z, guess);
}

bool MatrixFreeSystem::update_contacts(ImplicitContact& contacts, const Terrains& terrains,
                                       const VecX& b, const VecX& dv, bool commit, bool screening) {
  // The contacts' impulses need A dv at their particles only (a pin's impulse is not used).
  contact_rows_.clear();
  for (const auto& c : contacts.contacts())
    if (!c.pinned) contact_rows_.push_back(c.particle);
  band_->multiply_rows(dv, contact_rows_, az_, threads_);
  return contacts.update_from_product(terrains, b, dv, commit, az_, screening);
}

LinearResult MatrixFreeSystem::solve(const VecX& b, VecX& y, ImplicitContact* constraints,
                                     Real tolerance, bool resume) {
  auto start = Clock::now();
  // Block Jacobi: the inverses of the (filtered) diagonal blocks (kept when resuming); with
  // multigrid they are its finest smoother's, and its coarse operators are rebuilt when
  // kMultigridMaxAge says so or when the contacts' set is not theirs.
  LinearResult r;
  const int particles = band_->rows() / 3;
  const ProductFilter filter =
      constraints != nullptr ? constraints->product_filter() : ProductFilter{};
  if (!resume) {
    const auto diagonal = [&](int i, Real d[9]) {
      band_->diagonal_block(i, d);
      if (constraints != nullptr) constraints->filter_diagonal_block(i, d);
    };
    if (use_multigrid_) {
      r = multigrid_.set_diagonal_blocks(particles, diagonal, filter, threads_);
      contacts_now_.clear();
      if (constraints != nullptr)
        for (const ImplicitContact::Contact& c : constraints->contacts())
          contacts_now_.emplace_back(c.particle, c.pinned ? 2 : static_cast<int>(c.mode));
      if (r.ok() &&
          (coarse_stale_ || coarse_age_ >= kMultigridMaxAge || contacts_now_ != coarse_contacts_)) {
        multigrid_.set_operator(*band_, filter, threads_);
        coarse_contacts_ = contacts_now_;
        coarse_stale_ = false;
        coarse_age_ = 0;
        coarse_iterations_ = -1;
      }
    } else {
      r = cg_.set_diagonal_blocks(particles, diagonal, threads_);
    }
  }
  times_.factorization += seconds_since(start);
  if (!r.ok()) return r;
  start = Clock::now();
  const auto apply = [&](const VecX& in, VecX& out) { band_->multiply(in, out, threads_, filter); };
  // Resuming: from the iterate as CG left it (before the caller's corrections), with the
  // iterations the loose solve left, so that it is one solve in every respect.
  if (resume) y = cg_x_;
  const int done = resume ? loose_iterations_ : 0;
  const int limit = options_.cg_max_iterations - done;
  if (use_multigrid_) {
    const auto precondition = [&](const VecX& in, VecX& out) {
      multigrid_.apply(apply, in, out, threads_);
    };
    r = cg_.solve(apply, precondition, b, y, tolerance, limit, threads_, resume);
  } else {
    r = cg_.solve(apply, b, y, tolerance, limit, threads_, resume);
  }
  r.iterations += done;
  if (use_multigrid_ && tolerance <= options_.cg_tolerance) {
    // Coarse operators that need twice the iterations they needed when built: rebuilt.
    if (coarse_iterations_ < 0) {
      coarse_iterations_ = r.iterations;
    } else if (r.iterations > 2 * coarse_iterations_ + 2) {
      coarse_stale_ = true;
    }
  }
  if (!resume && tolerance > options_.cg_tolerance) {  // a loose solve: kept for resuming
    cg_x_ = y;
    loose_iterations_ = r.iterations;
  }
  times_.solve += seconds_since(start);
  return r;
}

}  // namespace jelly
