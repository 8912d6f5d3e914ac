#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/geometry/cube.hpp>

namespace jelly {
namespace {

using Dense = Eigen::MatrixXd;

Model cube_model(Real ks, Real kd) {
  CubeSpec spec;
  spec.n = 3;
  spec.edge_length = 1;
  for (auto& c : spec.springs) c = SpringCoefficients{ks, kd};
  return build_cube(spec);
}

// Positions displaced by up to `amplitude` (a fraction of the spacing 0.5), random velocities:
// some springs stretched, some compressed, some closing, some separating.
State random_state(const Model& model, int seed, Real amplitude = 0.15) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(model);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) {
    s.x[i] += amplitude * 0.5 * u(rng);
    s.v[i] = 2 * u(rng);
  }
  return s;
}

// Central differences of the full force f(x, v) with respect to x (wrt_x) or v.
Dense central_difference(const Model& model, const State& s, bool wrt_x) {
  const int n = model.num_dofs();
  Dense j(n, n);
  VecX fp(n), fm(n);
  const Real step = 1e-6;
  for (int c = 0; c < n; ++c) {
    VecX x = s.x, v = s.v;
    (wrt_x ? x : v)[c] += step;
    compute_forces(model, x, v, fp);
    (wrt_x ? x : v)[c] -= 2 * step;
    compute_forces(model, x, v, fm);
    j.col(c) = (fp - fm) / (2 * step);
  }
  return j;
}

struct Jacobians {
  Dense k, d;
};
Jacobians assembled(const Model& model, const State& s, JacobianOptions options) {
  SpringJacobian jacobian(model);
  SparseMatrix k = jacobian.make_matrix(), d = jacobian.make_matrix();
  jacobian.assemble(model, s.x, s.v, options, k, d);
  return {Dense(k), Dense(d)};
}

Real relative_error(const Dense& a, const Dense& b) { return (a - b).norm() / b.norm(); }

// With no definiteness fix and the exact damper term, K and D are the exact df/dx and df/dv.
TEST(SpringJacobian, ExactJacobiansMatchCentralDifferences) {
  for (const auto& [ks, kd] :
       {std::pair<Real, Real>{1400, 50}, {100000, 50}, {10, 20}, {2400, 120}}) {
    const Model model = cube_model(ks, kd);
    for (int seed : {1, 2, 3}) {
      const State s = random_state(model, seed);
      JacobianOptions exact;
      exact.definiteness = DefinitenessFix::kNone;
      exact.exact_damper = true;
      const Jacobians j = assembled(model, s, exact);
      EXPECT_LT(relative_error(j.k, central_difference(model, s, true)), 1e-7)
          << "ks " << ks << " kd " << kd << " seed " << seed;
      EXPECT_LT(relative_error(j.d, central_difference(model, s, false)), 1e-7);
      EXPECT_LT((j.d - j.d.transpose()).norm(), 1e-12 * j.d.norm());
    }
  }
}

// Without dampers the symmetric K (the solvers' K) is the exact df/dx; with dampers it differs
// from it exactly by the dropped non-symmetric term, and is symmetric.
TEST(SpringJacobian, SymmetricJacobianDropsOnlyTheDamperAsymmetry) {
  const Model undamped = cube_model(1400, 0);
  const State s = random_state(undamped, 4);
  JacobianOptions none;
  none.definiteness = DefinitenessFix::kNone;
  const Jacobians j = assembled(undamped, s, none);
  EXPECT_LT(relative_error(j.k, central_difference(undamped, s, true)), 1e-7);

  const Model damped = cube_model(1400, 50);
  const Jacobians sym = assembled(damped, s, none);
  JacobianOptions exact = none;
  exact.exact_damper = true;
  const Jacobians full = assembled(damped, s, exact);
  EXPECT_LT((sym.k - sym.k.transpose()).norm(), 1e-12 * sym.k.norm());
  EXPECT_GT((full.k - full.k.transpose()).norm(), 1e-6 * full.k.norm());
  // The symmetric part of the dropped term is what the exact K keeps beyond sym.k.
  EXPECT_LT(relative_error(sym.k, full.k), 0.2);
}

// A uniformly stretched, uniformly expanding cube has no compressed or closing spring: every
// policy gives the exact Jacobian.
TEST(SpringJacobian, PoliciesAgreeWhenNothingIsCompressed) {
  const Model model = cube_model(1400, 50);
  State s = rest_state(model);
  const Vec3 c(0.5, 1.0, 0.5);
  for (int i = 0; i < model.num_particles(); ++i) {
    particle(s.x, i) = c + 1.05 * (Vec3(particle(s.x, i)) - c);
    particle(s.v, i) = 0.3 * (Vec3(particle(s.x, i)) - c);
  }
  JacobianOptions none;
  none.definiteness = DefinitenessFix::kNone;
  const Dense exact = assembled(model, s, none).k;
  for (DefinitenessFix fix : {DefinitenessFix::kClampCompressed, DefinitenessFix::kProjectPsd}) {
    JacobianOptions o;
    o.definiteness = fix;
    EXPECT_LT(relative_error(assembled(model, s, o).k, exact), 1e-14) << definiteness_name(fix);
  }
  // ... and the exact one matches central differences of the forces without dampers.
  const Model undamped = cube_model(1400, 0);
  EXPECT_LT(relative_error(assembled(undamped, s, none).k, central_difference(undamped, s, true)),
            1e-7);
}

Real min_eigenvalue(const Dense& m) {
  return Eigen::SelfAdjointEigenSolver<Dense>(0.5 * (m + m.transpose())).eigenvalues().minCoeff();
}

// A crushed cube: -K is indefinite without a fix; clamp and project make it PSD.
TEST(SpringJacobian, DefinitenessFixesMakeMinusKPositiveSemidefinite) {
  const Model model = cube_model(1400, 50);
  State s = random_state(model, 5, 0.05);
  const Vec3 c(0.5, 1.0, 0.5);
  for (int i = 0; i < model.num_particles(); ++i)
    particle(s.x, i) = c + 0.5 * (Vec3(particle(s.x, i)) - c);
  JacobianOptions o;
  o.definiteness = DefinitenessFix::kNone;
  const Dense k_none = assembled(model, s, o).k;
  EXPECT_LT(min_eigenvalue(-k_none), -1.0);
  for (DefinitenessFix fix : {DefinitenessFix::kClampCompressed, DefinitenessFix::kProjectPsd}) {
    o.definiteness = fix;
    const Dense k = assembled(model, s, o).k;
    EXPECT_GT(min_eigenvalue(-k), -1e-9 * k.norm()) << definiteness_name(fix);
  }
}

// kProjectPsd equals the eigenvalue projection of each spring's exact symmetric 3x3 block.
TEST(SpringJacobian, ProjectionEqualsEigenvalueClampOfTheBlock) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    Model m;
    m.mass = VecX::Ones(2);
    m.rest_position = VecX::Zero(6);
    m.springs.add(0, 1, 1.0, {1400, 50}, SpringType::kStructural);
    State s;
    s.x = VecX::Zero(6);
    s.v = VecX::Zero(6);
    const Vec3 d = Vec3(u(rng), u(rng), u(rng)).normalized() * (0.5 + u(rng) * 0.4 + 0.5);
    s.x.segment<3>(3) = -d;
    s.v.segment<3>(0) = Vec3(u(rng), u(rng), u(rng)) * 3;
    JacobianOptions o;
    o.definiteness = DefinitenessFix::kNone;
    const Eigen::Matrix3d block = assembled(m, s, o).k.block<3, 3>(0, 0);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(-block);
    const Eigen::Matrix3d projected = eig.eigenvectors() *
                                      eig.eigenvalues().cwiseMax(0).asDiagonal() *
                                      eig.eigenvectors().transpose();
    o.definiteness = DefinitenessFix::kProjectPsd;
    const Eigen::Matrix3d fixed = assembled(m, s, o).k.block<3, 3>(0, 0);
    EXPECT_LT((-fixed - projected).norm(), 1e-10 * projected.norm() + 1e-12) << trial;
  }
}

// The one-pass system assembly equals M - alpha D - beta K and returns K w.
TEST(SpringJacobian, SystemAssemblyMatchesItsDefinition) {
  const Model model = cube_model(2400, 120);
  const State s = random_state(model, 6);
  SpringJacobian jacobian(model);
  // One 3x3 diagonal block per particle and four per spring, minus the shared diagonals.
  EXPECT_EQ(jacobian.non_zeros(), 9 * (model.num_particles() + 2 * model.springs.size()));
  SparseMatrix a = jacobian.make_matrix();
  const VecX w = VecX::Random(model.num_dofs());
  VecX kw(model.num_dofs());
  const Real alpha = 0.01, beta = 1e-4;
  JacobianOptions o;
  jacobian.assemble_system(model, s.x, s.v, o, alpha, beta, a, w, kw);
  const Jacobians j = assembled(model, s, o);
  Dense expected = -alpha * j.d - beta * j.k;
  for (int i = 0; i < model.num_dofs(); ++i) expected(i, i) += model.mass[i / 3];
  EXPECT_LT(relative_error(Dense(a), expected), 1e-14);
  EXPECT_LT((kw - j.k * w).norm(), 1e-12 * (j.k * w).norm());
  // Assembling again only refills the same pattern.
  const int* rows = a.innerIndexPtr();
  jacobian.assemble_system(model, s.x, s.v, o, alpha, beta, a, w, kw);
  EXPECT_EQ(rows, a.innerIndexPtr());
}

// The assembly is a gather per column (each spring's blocks computed for both columns): the same
// bits on 1, 2 and 3 threads.
TEST(SpringJacobian, AssemblyIsTheSameForAnyThreadCount) {
  CubeSpec spec;
  spec.n = 12;  // 1,728 particles: three column ranges
  const Model model = build_cube(spec);
  const State s = random_state(model, 7, 0.02);
  SpringJacobian jacobian(model);
  const VecX w = VecX::Random(model.num_dofs());
  SparseMatrix a1 = jacobian.make_matrix();
  VecX kw1(model.num_dofs());
  jacobian.assemble_system(model, s.x, s.v, JacobianOptions{}, 0.01, 1e-4, a1, w, kw1, 1);
  for (int threads : {2, 3}) {
    SparseMatrix a = jacobian.make_matrix();
    VecX kw(model.num_dofs());
    jacobian.assemble_system(model, s.x, s.v, JacobianOptions{}, 0.01, 1e-4, a, w, kw, threads);
    EXPECT_TRUE(std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), a1.valuePtr()));
    EXPECT_TRUE(kw == kw1) << threads;
  }
}

// The matrix-free system on the force loop's bands is the assembled A = M - alpha D - beta K:
// the same products, diagonal blocks and K w (to rounding), for each definiteness fix, and the
// same bits on 1, 2 and 3 threads.
TEST(BandSystem, ProductsEqualTheAssembledMatrix) {
  CubeSpec spec;
  spec.n = 12;  // 1,728 particles, about 26,000 spring slots: two thread ranges
  for (auto& c : spec.springs) c = SpringCoefficients{2400, 120};
  const Model model = build_cube(spec);
  const SpringBands bands(model);
  ASSERT_TRUE(bands.dense());
  const State s = random_state(model, 8, 0.1);  // some springs compressed, some stretched
  const VecX w = VecX::Random(model.num_dofs());
  const VecX p = VecX::Random(model.num_dofs());
  const Real alpha = 0.01, beta = 1e-4;
  SpringJacobian jacobian(model);
  for (DefinitenessFix fix :
       {DefinitenessFix::kClampCompressed, DefinitenessFix::kProjectPsd, DefinitenessFix::kNone}) {
    JacobianOptions o;
    o.definiteness = fix;
    SparseMatrix a = jacobian.make_matrix();
    VecX kw_expected(model.num_dofs());
    jacobian.assemble_system(model, s.x, s.v, o, alpha, beta, a, w, kw_expected);
    jacobian.add_to_diagonal(a, 3 * 5 + 1, 0.75);  // (a diagonal addition of particle 5)
    jacobian.add_to_diagonal(a, 3 * 5, 0.75);
    jacobian.add_to_diagonal(a, 3 * 5 + 2, 0.75);
    const VecX ap = a * p;
    VecX first_y, first_kw;
    for (int threads : {1, 2, 3}) {
      BandSystem system(bands, model.num_particles());
      VecX kw(model.num_dofs()), y(model.num_dofs());
      ASSERT_TRUE(system.assemble(model, s.x, s.v, fix, alpha, beta, w, kw, threads));
      system.add_diagonal(5, 0.75);
      system.multiply(p, y, threads);
      EXPECT_LT((y - ap).norm(), 1e-13 * ap.norm()) << definiteness_name(fix);
      EXPECT_LT((kw - kw_expected).norm(), 1e-13 * kw_expected.norm()) << definiteness_name(fix);
      for (int i : {0, 5, 700, model.num_particles() - 1}) {
        Real block[9];
        system.diagonal_block(i, block);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(block[3 * r + c], a.coeff(3 * i + r, 3 * i + c),
                        1e-13 * std::abs(a.coeff(3 * i, 3 * i)));
      }
      if (threads == 1) {
        first_y = y;
        first_kw = kw;
      } else {
        EXPECT_TRUE(y == first_y) << threads;
        EXPECT_TRUE(kw == first_kw) << threads;
      }
    }
  }
  // Single precision coefficients: the products within the coefficients' rounding (6e-8
  // relative per spring) of the assembled matrix's, the same bits on 1, 2 and 3 threads, and
  // multiply_rows gives multiply's rows bit for bit in both precisions.
  {
    JacobianOptions o;
    SparseMatrix a = jacobian.make_matrix();
    VecX kw_expected(model.num_dofs());
    jacobian.assemble_system(model, s.x, s.v, o, alpha, beta, a, w, kw_expected);
    const VecX ap = a * p;
    const std::vector<int> rows = {0, 5, 700, 1000, model.num_particles() - 1};
    for (bool single : {false, true}) {
      VecX first_y;
      for (int threads : {1, 2, 3}) {
        BandSystem system(bands, model.num_particles(), single);
        EXPECT_EQ(system.single_precision(), single);
        VecX kw(model.num_dofs()), y(model.num_dofs());
        ASSERT_TRUE(system.assemble(model, s.x, s.v, o.definiteness, alpha, beta, w, kw, threads));
        system.multiply(p, y, threads);
        const Real tolerance = single ? 1e-7 : 1e-13;
        EXPECT_LT((y - ap).norm(), tolerance * ap.norm()) << single;
        if (single) {
          EXPECT_GT((y - ap).norm(), 1e-13 * ap.norm());  // floats were used
        }
        VecX rows_only = VecX::Constant(model.num_dofs(), -1.0);
        system.multiply_rows(p, rows, rows_only);
        for (int i : rows) EXPECT_TRUE(rows_only.segment<3>(3 * i) == y.segment<3>(3 * i)) << i;
        EXPECT_EQ(rows_only[3], -1.0);  // other rows untouched
        if (threads == 1) {
          first_y = y;
        } else {
          EXPECT_TRUE(y == first_y) << threads;
        }
      }
    }
  }
  // A collapsed spring has no direction here: assemble says so (the caller falls back).
  State collapsed = s;
  particle(collapsed.x, 1) = particle(collapsed.x, 0);
  BandSystem system(bands, model.num_particles());
  VecX kw(model.num_dofs());
  EXPECT_FALSE(system.assemble(model, collapsed.x, s.v, DefinitenessFix::kClampCompressed, alpha,
                               beta, w, kw, 1));
}

// The contact filter of implicit_euler as the product applies it (ProductFilter): the input
// q = p with q_i = S_i p_i and the output y_i = S_i (A q)_i + c_i S_i p_i + (p_i - S_i p_i) at
// the filtered particles, against that formula on the assembled matrix; and with a few hundred
// particles filtered (more than one thread's worth of rows for multiply_rows), the same bits on
// 1, 2 and 3 threads, over repeated calls (the balanced split moves between them) and for any
// size of the product's blocks.
TEST(BandSystem, FilteredProductsAndRowsAreTheSameOnAnyThreadCount) {
  CubeSpec spec;
  spec.n = 12;  // 1,728 particles
  for (auto& c : spec.springs) c = SpringCoefficients{2400, 120};
  const Model model = build_cube(spec);
  const SpringBands bands(model);
  const State s = random_state(model, 9, 0.1);
  const VecX p = VecX::Random(model.num_dofs());
  const Real alpha = 0.01, beta = 1e-4;
  const int np = model.num_particles();
  // Every third particle filtered (576, across every thread boundary): sliding (a tangent
  // plane and a viscosity), sticking or pinned (S = 0) in turn.
  std::vector<int> slot(np, -1), rows;
  std::vector<Real> map, scale;
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  for (int i = 0; i < np; i += 3) {
    slot[i] = static_cast<int>(rows.size());
    rows.push_back(i);
    Eigen::Matrix3d projector = Eigen::Matrix3d::Zero();
    Real c = 0;
    if (rows.size() % 2 == 1) {
      const Vec3 normal = Vec3(u(rng), u(rng), u(rng)).normalized();
      projector = Eigen::Matrix3d::Identity() - normal * normal.transpose();
      c = 5 * (1 + u(rng));
    }
    map.insert(map.end(), projector.data(), projector.data() + 9);
    scale.push_back(c);
  }
  ASSERT_GT(rows.size(), 256U);  // multiply_rows splits from 128 rows per thread
  const ProductFilter filter{slot.data(), map.data(), scale.data()};

  SpringJacobian jacobian(model);
  JacobianOptions o;
  SparseMatrix a = jacobian.make_matrix();
  VecX kw_expected(model.num_dofs());
  jacobian.assemble_system(model, s.x, s.v, o, alpha, beta, a, p, kw_expected);
  VecX q = p;
  for (int i : rows) {
    const Eigen::Map<const Eigen::Matrix3d> projector(map.data() + 9 * slot[i]);
    q.segment<3>(3 * i) = projector * p.segment<3>(3 * i);
  }
  VecX expected = a * q;
  for (int i : rows) {
    const Eigen::Map<const Eigen::Matrix3d> projector(map.data() + 9 * slot[i]);
    const Vec3 pi = p.segment<3>(3 * i), si = projector * pi;
    expected.segment<3>(3 * i) =
        projector * expected.segment<3>(3 * i) + scale[slot[i]] * si + (pi - si);
  }

  VecX first_y, first_rows, first_kw;
  std::vector<Real> first_diagonal;
  for (int threads : {1, 2, 3}) {
    BandSystem system(bands, np);
    VecX kw(model.num_dofs());
    ASSERT_TRUE(system.assemble(model, s.x, s.v, o.definiteness, alpha, beta, p, kw, threads));
    // The rows' blocks: one for the whole cube (the default at this size), blocks longer and
    // shorter than the largest band offset (288), and a block of one particle; assembled again
    // with each, the same K w and diagonal blocks too.
    const int whole_block = system.row_block();
    EXPECT_GE(whole_block, np);
    for (int block : {whole_block, 500, 100, 1}) {
      system.set_row_block(block);
      VecX kw_again(model.num_dofs());
      ASSERT_TRUE(
          system.assemble(model, s.x, s.v, o.definiteness, alpha, beta, p, kw_again, threads));
      if (first_kw.size() == 0) first_kw = kw_again;
      EXPECT_TRUE(kw_again == first_kw) << threads << " threads, block " << block;
      std::vector<Real> diagonal;
      for (int i : {0, 143, 144, 700, np - 1}) {
        Real d[9];
        system.diagonal_block(i, d);
        diagonal.insert(diagonal.end(), d, d + 9);
      }
      if (first_diagonal.empty()) first_diagonal = diagonal;
      EXPECT_TRUE(diagonal == first_diagonal) << threads << " threads, block " << block;
      for (int call = 0; call < 3; ++call) {
        VecX y(model.num_dofs());
        system.multiply(p, y, threads, filter);
        EXPECT_LT((y - expected).norm(), 1e-13 * expected.norm()) << threads;
        if (first_y.size() == 0) first_y = y;
        EXPECT_TRUE(y == first_y) << threads << " threads, block " << block << ", call " << call;
      }
    }
    system.set_row_block(whole_block);
    // The rows alone, on up to `threads` threads: the unfiltered product's rows, bit for bit.
    VecX whole(model.num_dofs());
    system.multiply(p, whole, threads);
    VecX rows_only = VecX::Constant(model.num_dofs(), -1.0);
    system.multiply_rows(p, rows, rows_only, threads);
    for (int i : rows) EXPECT_TRUE(rows_only.segment<3>(3 * i) == whole.segment<3>(3 * i)) << i;
    EXPECT_EQ(rows_only[3], -1.0);  // particle 1 is not a row
    if (first_rows.size() == 0) first_rows = rows_only;
    EXPECT_TRUE(rows_only == first_rows) << threads;
  }
}

// Extra blocks (pairs without a spring) are in the pattern and zero after every assembly.
TEST(SpringJacobian, ExtraBlocksAreZero) {
  const Model model = cube_model(2400, 120);
  const State s = random_state(model, 9);
  const int far = model.num_particles() - 1;  // opposite corners: no spring joins them
  SpringJacobian plain(model), extended(model, {{0, far}});
  EXPECT_EQ(extended.non_zeros(), plain.non_zeros() + 18);
  SparseMatrix a = plain.make_matrix(), b = extended.make_matrix();
  const VecX w = VecX::Random(model.num_dofs());
  VecX kwa(model.num_dofs()), kwb(model.num_dofs());
  plain.assemble_system(model, s.x, s.v, JacobianOptions{}, 0.01, 1e-4, a, w, kwa);
  std::fill(b.valuePtr(), b.valuePtr() + b.nonZeros(), 1.0);
  extended.assemble_system(model, s.x, s.v, JacobianOptions{}, 0.01, 1e-4, b, w, kwb);
  EXPECT_EQ(Dense(a), Dense(b));
  EXPECT_TRUE(kwa == kwb);
  EXPECT_EQ(b.coeff(0, 3 * far), 0.0);
}

TEST(SpringJacobian, DefinitenessNamesRoundTrip) {
  for (DefinitenessFix f :
       {DefinitenessFix::kClampCompressed, DefinitenessFix::kProjectPsd, DefinitenessFix::kNone}) {
    EXPECT_EQ(value_of(definiteness_fixes(), definiteness_name(f), "definiteness"), f);
  }
  EXPECT_THROW(value_of(definiteness_fixes(), "psd", "definiteness"), InputError);
}

}  // namespace
}  // namespace jelly
