#include <jelly/solvers/arkode/detail/arkode_iterative.hpp>

#include <Eigen/LU>
#include <cmath>
#include <memory>

#include <arkode/arkode_arkstep.h>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>

namespace jelly::arkode {

namespace {
using Block = Eigen::Map<const Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>;
using MutableBlock = Eigen::Map<Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>;
}  // namespace

namespace {
// The 6 values xx, xy, xz, yy, yz, zz of a symmetric 3x3 row-major block.
inline void pack(const Real* b, Real* out) {
  out[0] = b[0];
  out[1] = b[1];
  out[2] = b[2];
  out[3] = b[4];
  out[4] = b[5];
  out[5] = b[8];
}
}  // namespace

void SpringOperator::linearize(const Model& model, const VecX& x, const VecX& v,
                               const AnchorSprings* anchors, Real t, const ForceJacobian* forces) {
  spring_jacobian_blocks(model, x, v, JacobianOptions{}, k_blocks_, d_blocks_);
  const Springs& s = model.springs;
  const size_t blocks = 9 * static_cast<size_t>(model.num_particles());
  k_diagonal_.assign(blocks, 0.0);
  d_diagonal_.assign(blocks, 0.0);
  spring_.resize(12 * static_cast<size_t>(s.size()));
  for (int sp = 0; sp < s.size(); ++sp) {
    const Real* k = &k_blocks_[9 * static_cast<size_t>(sp)];
    const Real* d = &d_blocks_[9 * static_cast<size_t>(sp)];
    pack(k, &spring_[12 * static_cast<size_t>(sp)]);
    pack(d, &spring_[12 * static_cast<size_t>(sp) + 6]);
    for (const int p : {s.a[sp], s.b[sp]}) {
      Real* kp = &k_diagonal_[9 * static_cast<size_t>(p)];
      Real* dp = &d_diagonal_[9 * static_cast<size_t>(p)];
      for (int e = 0; e < 9; ++e) {
        kp[e] += k[e];
        dp[e] += d[e];
      }
    }
  }
  anchors_.clear();
  if (anchors) {
    anchors_ = *anchors;
    for (const AnchorSpring& a : anchors_) {
      for (int c = 0; c < 3; ++c) {
        k_diagonal_[9 * static_cast<size_t>(a.particle) + 4 * c] -= a.stiffness;
        d_diagonal_[9 * static_cast<size_t>(a.particle) + 4 * c] -= a.damping;
      }
    }
  }
  // The added forces' blocks: the symmetric part of a block on the diagonal goes to K's and
  // D's diagonal blocks; products take every block (multiply_s, multiply_k).
  forces_.clear();
  if (forces != nullptr) {
    for (const ForceJacobian::Block& b : forces->blocks()) {
      forces_.add(b.i, b.j, b.dfdx, b.dfdv);
      if (b.i != b.j) continue;
      MutableBlock(&k_diagonal_[9 * static_cast<size_t>(b.i)]) +=
          0.5 * (b.dfdx + b.dfdx.transpose());
      MutableBlock(&d_diagonal_[9 * static_cast<size_t>(b.i)]) +=
          0.5 * (b.dfdv + b.dfdv.transpose());
    }
  }
  // Wind drag: d(f)/d(v) = -drag I on its particles.
  dragged_.clear();
  drag_.clear();
  if (!model.external_forces.empty()) {
    damping_.setZero(model.num_particles());
    add_external_damping(model.external_forces, t, damping_);
    for (int i = 0; i < model.num_particles(); ++i) {
      if (damping_[i] == 0) continue;
      dragged_.push_back(i);
      drag_.push_back(damping_[i]);
      for (int c = 0; c < 3; ++c) d_diagonal_[9 * static_cast<size_t>(i) + 4 * c] -= damping_[i];
    }
  }
  pinned_ = model.pins.particles;
  is_pinned_.assign(static_cast<size_t>(model.num_particles()), 0);
  for (const int p : pinned_) is_pinned_[static_cast<size_t>(p)] = 1;
  s_.resize(6 * static_cast<size_t>(s.size()));
  s_inverse_.resize(blocks);
  constraints_.clear();
  constraint_of_.assign(static_cast<size_t>(model.num_particles()), -1);
  gamma_ = -1;
  ready_ = true;
  ++linearizations_;
}

void SpringOperator::set_constraints(std::vector<Constraint> constraints) {
  constraints_ = std::move(constraints);
  for (size_t c = 0; c < constraints_.size(); ++c)
    constraint_of_[static_cast<size_t>(constraints_[c].particle)] = static_cast<int>(c);
  gamma_ = -1;
}

void SpringOperator::set_gamma(const Model& model, Real gamma) {
  if (gamma == gamma_) return;
  const Real g2 = gamma * gamma;
  const size_t springs = s_.size() / 6;
  for (size_t sp = 0; sp < springs; ++sp) {
    const Real* k = &spring_[12 * sp];
    const Real* d = k + 6;
    Real* out = &s_[6 * sp];
    for (int e = 0; e < 6; ++e) out[e] = -gamma * d[e] - g2 * k[e];
  }
  for (int i = 0; i < model.num_particles(); ++i) {
    Eigen::Matrix3d block = model.mass[i] * Eigen::Matrix3d::Identity() -
                            gamma * Block(&d_diagonal_[9 * static_cast<size_t>(i)]) -
                            g2 * Block(&k_diagonal_[9 * static_cast<size_t>(i)]);
    const int c = constraint_of_[static_cast<size_t>(i)];
    if (is_pinned_[static_cast<size_t>(i)]) {
      block.setIdentity();  // P = 0: the velocity change is prescribed
    } else if (c >= 0) {
      // P S_ii P + n n^T.
      const Vec3& n = constraints_[static_cast<size_t>(c)].normal;
      const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - n * n.transpose();
      block = p * (block + gamma * constraints_[static_cast<size_t>(c)].damping * p) * p +
              n * n.transpose();
    }
    MutableBlock inverse(&s_inverse_[9 * static_cast<size_t>(i)]);
    inverse = block.inverse();
  }
  gamma_ = gamma;
}

namespace {
// out = M p + sum over springs of the symmetric blocks b_k (6 values each, at `stride`) applied
// to (p_a - p_b), added to a and subtracted from b; M p only when `mass` is set.
void spring_product(const Model& model, const Real* blocks, size_t stride, const Real* p, bool mass,
                    VecX& out) {
  ensure_size(out, model.num_dofs());
  Real* o = out.data();
  if (mass) {
    for (int i = 0; i < model.num_particles(); ++i)
      for (int c = 0; c < 3; ++c) o[3 * i + c] = model.mass[i] * p[3 * i + c];
  } else {
    out.setZero();
  }
  const Springs& s = model.springs;
  const int* a = s.a.data();
  const int* b = s.b.data();
  const Real* bk = blocks;
  for (int sp = 0; sp < s.size(); ++sp, bk += stride) {
    const int ia = 3 * a[sp], ib = 3 * b[sp];
    const Real d0 = p[ia] - p[ib], d1 = p[ia + 1] - p[ib + 1], d2 = p[ia + 2] - p[ib + 2];
    const Real y0 = bk[0] * d0 + bk[1] * d1 + bk[2] * d2;
    const Real y1 = bk[1] * d0 + bk[3] * d1 + bk[4] * d2;
    const Real y2 = bk[2] * d0 + bk[4] * d1 + bk[5] * d2;
    o[ia] += y0;
    o[ia + 1] += y1;
    o[ia + 2] += y2;
    o[ib] -= y0;
    o[ib + 1] -= y1;
    o[ib + 2] -= y2;
  }
}
}  // namespace

void SpringOperator::multiply_s(const Model& model, const VecX& p, VecX& out) const {
  spring_product(model, s_.data(), 6, p.data(), true, out);
  for (const AnchorSpring& a : anchors_)
    out.segment<3>(3 * a.particle) +=
        (gamma_ * a.damping + gamma_ * gamma_ * a.stiffness) * p.segment<3>(3 * a.particle);
  for (size_t k = 0; k < dragged_.size(); ++k)
    out.segment<3>(3 * dragged_[k]) += gamma_ * drag_[k] * p.segment<3>(3 * dragged_[k]);
  // S -= gamma S_D + gamma^2 S_K for the added forces (S_ the symmetric parts).
  for (const ForceJacobian::Block& b : forces_.blocks()) {
    const Eigen::Matrix3d a = -0.5 * (gamma_ * b.dfdv + gamma_ * gamma_ * b.dfdx);
    out.segment<3>(3 * b.i) += a * p.segment<3>(3 * b.j);
    out.segment<3>(3 * b.j) += a.transpose() * p.segment<3>(3 * b.i);
  }
}

void SpringOperator::multiply_k(const Model& model, const Real* p, VecX& out) const {
  spring_product(model, spring_.data(), 12, p, false, out);
  for (const AnchorSpring& a : anchors_)
    for (int c = 0; c < 3; ++c) out[3 * a.particle + c] -= a.stiffness * p[3 * a.particle + c];
  for (const ForceJacobian::Block& b : forces_.blocks()) {
    const Eigen::Map<const Vec3> pi(p + 3 * b.i), pj(p + 3 * b.j);
    out.segment<3>(3 * b.i) += 0.5 * b.dfdx * pj;
    out.segment<3>(3 * b.j) += 0.5 * b.dfdx.transpose() * pi;
  }
}

void SpringOperator::filter(VecX& r) const {
  for (const Constraint& c : constraints_) {
    auto ri = r.segment<3>(3 * c.particle);
    ri -= c.normal.dot(ri) * c.normal;
  }
  for (const int p : pinned_) r.segment<3>(3 * p).setZero();
}

void SpringOperator::prescribed(const Real* bv, VecX& z) const {
  z.setZero();
  for (const Constraint& k : constraints_) {
    const Eigen::Map<const Vec3> b(bv + 3 * k.particle);
    z.segment<3>(3 * k.particle) = k.normal.dot(b) * k.normal;
  }
  for (const int p : pinned_) z.segment<3>(3 * p) = Eigen::Map<const Vec3>(bv + 3 * p);
}

void SpringOperator::multiply_filtered(const Model& model, const VecX& y, VecX& out) {
  if (!filters()) {
    multiply_s(model, y, out);
    return;
  }
  filtered_ = y;
  filter(filtered_);
  multiply_s(model, filtered_, out);
  filter(out);
  for (const Constraint& c : constraints_) {
    const auto yi = y.segment<3>(3 * c.particle);
    const Real yn = c.normal.dot(yi);
    // The normal component passes through; the friction damps the tangential one.
    out.segment<3>(3 * c.particle) += yn * c.normal + gamma_ * c.damping * (yi - yn * c.normal);
  }
  for (const int p : pinned_) out.segment<3>(3 * p) = y.segment<3>(3 * p);
}

void SpringOperator::precondition(const VecX& r, VecX& z) const {
  ensure_size(z, r.size());
  const Eigen::Index particles = r.size() / 3;
  for (Eigen::Index i = 0; i < particles; ++i)
    z.segment<3>(3 * i) = Block(&s_inverse_[9 * static_cast<size_t>(i)]) * r.segment<3>(3 * i);
}

void SpringOperator::block_jacobi(const Model& model, const Real* r, Real* z) const {
  const Eigen::Index n = model.num_dofs();
  for (int i = 0; i < model.num_particles(); ++i) {
    const size_t at = 9 * static_cast<size_t>(i);
    const Eigen::Vector3d rx(r[3 * i], r[3 * i + 1], r[3 * i + 2]);
    const Eigen::Vector3d rv(r[n + 3 * i], r[n + 3 * i + 1], r[n + 3 * i + 2]);
    Eigen::Vector3d rhs = model.mass[i] * rv + gamma_ * (Block(&k_diagonal_[at]) * rx);
    Eigen::Vector3d dv;
    const int c = constraint_of_[static_cast<size_t>(i)];
    if (is_pinned_[static_cast<size_t>(i)]) {
      dv = rv;  // the pinned particle's velocity change is prescribed
    } else if (c < 0) {
      dv = Block(&s_inverse_[at]) * rhs;
    } else {
      // dv = y + z, z = n (n.rv), (P S_ii P + n n^T) y = P (rhs - S_ii z).
      const Vec3& nn = constraints_[static_cast<size_t>(c)].normal;
      const Eigen::Vector3d zz = nn.dot(rv) * nn;
      const Eigen::Matrix3d s_ii = model.mass[i] * Eigen::Matrix3d::Identity() -
                                   gamma_ * Block(&d_diagonal_[at]) -
                                   gamma_ * gamma_ * Block(&k_diagonal_[at]) +
                                   gamma_ * constraints_[static_cast<size_t>(c)].damping *
                                       (Eigen::Matrix3d::Identity() - nn * nn.transpose());
      rhs -= s_ii * zz;
      rhs -= nn.dot(rhs) * nn;
      dv = Block(&s_inverse_[at]) * rhs + zz;
    }
    const Eigen::Vector3d dx = rx + gamma_ * dv;
    for (int k = 0; k < 3; ++k) {
      z[3 * i + k] = dx[k];
      z[n + 3 * i + k] = dv[k];
    }
  }
}

namespace {

constexpr int kMaxCgIterations = 200;
// When ARKODE passes no tolerance (0): relative to the right-hand side.
constexpr Real kFallbackTolerance = 1e-10;

struct IterativeContent {
  void* arkode_memory = nullptr;
  const RhsData* data = nullptr;
  IterativeMode mode = IterativeMode::kCg;
  SpringOperator op;
  ForceJacobian forces;  // the added forces' blocks at the linearization
  VecX x, v, f, rhs, prescribed, dv, r, z, p, q;
  IterativeStatistics statistics;
  int last_iterations = 0;
  Real last_residual = 0;
  long last_flag = 0;
};

IterativeContent& content(SUNLinearSolver s) { return *static_cast<IterativeContent*>(s->content); }

SUNLinearSolver_Type get_type(SUNLinearSolver) { return SUNLINEARSOLVER_ITERATIVE; }
SUNLinearSolver_ID get_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return SUNLS_SUCCESS; }
int set_atimes(SUNLinearSolver, void*, SUNATimesFn) { return SUNLS_SUCCESS; }
int set_preconditioner(SUNLinearSolver, void*, SUNPSetupFn, SUNPSolveFn) { return SUNLS_SUCCESS; }
int num_iterations(SUNLinearSolver s) { return content(s).last_iterations; }
realtype residual_norm(SUNLinearSolver s) { return content(s).last_residual; }
sunindextype last_flag(SUNLinearSolver s) { return content(s).last_flag; }

int setup(SUNLinearSolver s, SUNMatrix /*unused*/) {
  IterativeContent& c = content(s);
  const Model& model = c.data->dynamics->model();
  const Eigen::Index n = model.num_dofs();
  N_Vector y = nullptr;
  if (ARKStepGetCurrentState(c.arkode_memory, &y) != ARK_SUCCESS) {
    c.last_flag = SUNLS_MEM_NULL;
    return SUNLS_MEM_NULL;
  }
  const Eigen::Map<const VecX> yy(N_VGetArrayPointer(y), 2 * n);
  c.x = yy.head(n);
  c.v = yy.tail(n);
  realtype t = 0;
  ARKStepGetCurrentTime(c.arkode_memory, &t);
  c.data->dynamics->added_force_jacobians(t, c.x, c.v, c.forces);
  c.op.linearize(model, c.x, c.v, c.data->dynamics->anchors(), t, &c.forces);
  // The seed contacts whose force pushes into the surface at this iterate (see SpringOperator).
  const auto& seed = c.data->dynamics->contacts().seed_contacts();
  if (!seed.empty()) {
    ensure_size(c.f, n);
    compute_forces(model, c.x, c.v, c.f);
    std::vector<SpringOperator::Constraint> constraints;
    for (const ContactSolver::SeedContact& contact : seed) {
      const Real fn = particle(c.f, contact.particle).dot(contact.normal);
      if (fn < 0) constraints.push_back({contact.particle, contact.normal, -contact.friction * fn});
    }
    c.op.set_constraints(std::move(constraints));
  }
  ++c.statistics.setups;
  c.last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

// |M^-1 r|_2: the norm of the 6N residual [0; M^-1 r] that a Schur-reduced solve leaves.
Real weighted_residual(const Model& model, const VecX& r) {
  Real sum = 0;
  for (int i = 0; i < model.num_particles(); ++i)
    sum += r.segment<3>(3 * i).squaredNorm() / (model.mass[i] * model.mass[i]);
  return std::sqrt(sum);
}

// Preconditioned CG on S dv = rhs from dv = 0 until |M^-1 (rhs - S dv)| <= tol.
int conjugate_gradients(IterativeContent& c, const Model& model, Real tol) {
  const Eigen::Index n = model.num_dofs();
  ensure_size(c.dv, n);
  c.dv.setZero();
  c.r = c.rhs;
  Real residual = weighted_residual(model, c.r);
  if (!(tol > 0)) tol = kFallbackTolerance * residual;
  Real rz_old = 0;
  int it = 0;
  for (; residual > tol; ++it) {
    if (it == kMaxCgIterations) {
      c.last_iterations = it;
      c.last_residual = residual;
      ++c.statistics.failures;
      return SUNLS_CONV_FAIL;
    }
    c.op.precondition(c.r, c.z);
    const Real rz = c.r.dot(c.z);
    if (it == 0)
      c.p = c.z;
    else
      c.p = c.z + (rz / rz_old) * c.p;
    rz_old = rz;
    c.op.multiply_filtered(model, c.p, c.q);
    const Real pq = c.p.dot(c.q);
    if (!(pq > 0)) {
      // S is SPD with the definiteness fix; a non-positive curvature means a broken state
      // (non-finite values): ARKODE retries with a smaller step.
      c.last_iterations = it;
      ++c.statistics.failures;
      return SUNLS_PACKAGE_FAIL_REC;
    }
    const Real alpha = rz / pq;
    c.dv += alpha * c.p;
    c.r -= alpha * c.q;
    residual = weighted_residual(model, c.r);
  }
  c.last_iterations = it;
  c.last_residual = residual;
  c.statistics.iterations += it;
  return SUNLS_SUCCESS;
}

int solve(SUNLinearSolver s, SUNMatrix /*unused*/, N_Vector x, N_Vector b, realtype tol) {
  IterativeContent& c = content(s);
  Real gamma = 0;
  if (!c.op.ready() || ARKStepGetCurrentGamma(c.arkode_memory, &gamma) != ARK_SUCCESS) {
    c.last_flag = SUNLS_MEM_NULL;
    return SUNLS_MEM_NULL;
  }
  const Model& model = c.data->dynamics->model();
  const Eigen::Index n = model.num_dofs();
  c.op.set_gamma(model, gamma);
  ++c.statistics.solves;
  const Real* bb = N_VGetArrayPointer(b);
  Real* xx = N_VGetArrayPointer(x);
  if (c.mode == IterativeMode::kJacobi) {
    c.op.block_jacobi(model, bb, xx);
    c.last_iterations = 1;
    c.last_flag = SUNLS_SUCCESS;
    return SUNLS_SUCCESS;
  }
  // rhs = M bv + gamma K bx; with constraints P (rhs - S z), z_i = n (n.bv_i), dv = y + z.
  c.op.multiply_k(model, bb, c.rhs);
  for (int i = 0; i < model.num_particles(); ++i)
    for (int k = 0; k < 3; ++k)
      c.rhs[3 * i + k] = gamma * c.rhs[3 * i + k] + model.mass[i] * bb[n + 3 * i + k];
  const bool filtered = c.op.filters();
  if (filtered) {
    ensure_size(c.prescribed, n);
    c.op.prescribed(bb + n, c.prescribed);
    c.op.multiply_s(model, c.prescribed, c.q);
    c.rhs -= c.q;
    c.op.filter(c.rhs);
  }
  const int flag = conjugate_gradients(c, model, tol);
  if (filtered) c.dv += c.prescribed;
  // The iterate is returned even when CG did not converge (ARKODE then retries).
  for (Eigen::Index k = 0; k < n; ++k) {
    xx[k] = bb[k] + gamma * c.dv[k];
    xx[n + k] = c.dv[k];
  }
  c.last_flag = flag;
  return flag;
}

int free_solver(SUNLinearSolver s) {
  if (s == nullptr) return SUNLS_SUCCESS;
  delete static_cast<IterativeContent*>(s->content);
  s->content = nullptr;
  SUNLinSolFreeEmpty(s);
  return SUNLS_SUCCESS;
}

}  // namespace

LinearSolverPtr make_iterative_solver(SUNContext context, void* arkode_memory, const RhsData* data,
                                      IterativeMode mode) {
  auto c = std::make_unique<IterativeContent>();
  c->arkode_memory = arkode_memory;
  c->data = data;
  c->mode = mode;
  SUNLinearSolver s = SUNLinSolNewEmpty(context);
  if (s == nullptr) return nullptr;
  s->content = c.release();
  s->ops->gettype = get_type;
  s->ops->getid = get_id;
  s->ops->initialize = initialize;
  s->ops->setatimes = set_atimes;
  s->ops->setpreconditioner = set_preconditioner;
  s->ops->numiters = num_iterations;
  s->ops->resnorm = residual_norm;
  s->ops->setup = setup;
  s->ops->solve = solve;
  s->ops->lastflag = last_flag;
  s->ops->free = free_solver;
  return LinearSolverPtr(s);
}

const IterativeStatistics& iterative_statistics(SUNLinearSolver solver) {
  return content(solver).statistics;
}

}  // namespace jelly::arkode
