#include <jelly/solvers/linear/detail/lattice_multigrid.hpp>

#include <random>

#include <gtest/gtest.h>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>

namespace jelly {
namespace {

// The matrix-free backward-Euler system of an n^3 seed cube (edge 4, mass 1 per particle) of
// stiffness ks at step h, at a deformed, moving state (seeded), with an optional contact
// filter: every seventh particle of the bottom layer pinned (S = 0), the others of that layer
// sliding on a 20 degree slope (S = I - n n^T, friction viscosity 3).
struct MgProblem {
  Model model;
  std::unique_ptr<SpringBands> bands;
  std::unique_ptr<BandSystem> system;
  std::vector<int> slot;
  std::vector<Real> map, scale;
  ProductFilter filter;
  VecX b;

  MgProblem(int n, Real ks, Real h, bool constrained) {
    CubeSpec spec;
    spec.n = n;
    for (auto& c : spec.springs) c = SpringCoefficients{ks, 50};
    model = build_cube(spec);
    bands = std::make_unique<SpringBands>(model);
    State s = rest_state(model);
    std::mt19937 rng(7);
    std::uniform_real_distribution<Real> u(-1, 1);
    const Real spacing = 4.0 / (n - 1);
    for (int k = 0; k < model.num_dofs(); ++k) {
      s.x[k] += 0.05 * spacing * u(rng);
      s.v[k] = 0.5 * u(rng);
    }
    system = std::make_unique<BandSystem>(*bands, model.num_particles(), true);
    VecX kw(model.num_dofs());
    EXPECT_TRUE(
        system->assemble(model, s.x, s.v, DefinitenessFix::kClampCompressed, h, h * h, s.v, kw, 1));
    b.resize(model.num_dofs());
    for (int k = 0; k < b.size(); ++k) b[k] = u(rng);
    slot.assign(model.num_particles(), -1);
    if (constrained) {
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < n; ++k) {
          const int p = cube_index(n, i, 0, k);
          const int c = static_cast<int>(scale.size());
          slot[p] = c;
          Mat3 s3 = Mat3::Identity();
          if (p % 7 == 0) {
            s3.setZero();
            scale.push_back(0);
          } else {  // the seed slope's normal
            const Vec3 normal(std::sin(0.349), std::cos(0.349), 0);
            s3 -= normal * normal.transpose();
            scale.push_back(3);
          }
          map.insert(map.end(), s3.data(), s3.data() + 9);
        }
      filter = ProductFilter{slot.data(), map.data(), scale.data()};
      for (int p = 0; p < model.num_particles(); ++p)  // the right-hand side of a filtered system
        if (slot[p] >= 0)
          b.segment<3>(3 * p) =
              Eigen::Map<const Mat3>(&map[9 * slot[p]]) * Vec3(b.segment<3>(3 * p));
    }
  }
  // The filtered diagonal block S D S + c S + I - S.
  void diagonal(int i, Real d[9]) const {
    system->diagonal_block(i, d);
    if (slot[i] < 0) return;
    const Mat3 s = Eigen::Map<const Mat3>(&map[9 * slot[i]]);
    Mat3 block = Eigen::Map<const Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>(d);
    block = s * block * s + scale[slot[i]] * s + (Mat3::Identity() - s);
    Eigen::Map<Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>> out(d);
    out = block;
  }
  void multiply(const VecX& in, VecX& out, int threads) const {
    system->multiply(in, out, threads, filter);
  }
  // The V-cycle for this system on `threads` threads.
  void set_up(LatticeMultigrid& mg, int threads) const {
    ASSERT_TRUE(mg.build(model, *bands));
    ASSERT_TRUE(
        mg.set_diagonal_blocks(
              model.num_particles(), [&](int i, Real d[9]) { diagonal(i, d); }, filter, threads)
            .ok());
    mg.set_operator(*system, filter, threads);
  }
  // CG iterations to `tolerance` from zero, with the V-cycle (or block Jacobi); x the solution.
  int cg_iterations(bool multigrid, Real tolerance, int threads, VecX& x) const {
    MatrixFreeCg cg;
    const auto apply = [&](const VecX& in, VecX& out) { multiply(in, out, threads); };
    x.setZero(b.size());
    LinearResult r;
    if (multigrid) {
      LatticeMultigrid mg;
      set_up(mg, threads);
      r = cg.solve(
          apply, [&](const VecX& in, VecX& out) { mg.apply(apply, in, out, threads); }, b, x,
          tolerance, 1000, threads);
    } else {
      EXPECT_TRUE(cg.set_diagonal_blocks(
                        model.num_particles(), [&](int i, Real d[9]) { diagonal(i, d); }, threads)
                      .ok());
      r = cg.solve(apply, b, x, tolerance, 1000, threads);
    }
    EXPECT_TRUE(r.ok()) << r.message;
    return r.iterations;
  }
};

// The V-cycle is a symmetric positive definite operator (what CG needs of a preconditioner):
// <B x, y> = <x, B y> to rounding and x^T B x > 0 on random vectors, with and without contacts.
TEST(LatticeMultigrid, VCycleIsSymmetricPositiveDefinite) {
  for (bool constrained : {false, true}) {
    for (Real ks : {1400.0, 1e6}) {
      const MgProblem p(11, ks, 1.0 / 60, constrained);
      LatticeMultigrid mg;
      p.set_up(mg, 1);
      EXPECT_GE(mg.levels(), 3);
      const auto apply = [&](const VecX& in, VecX& out) { p.multiply(in, out, 1); };
      std::mt19937 rng(11);
      std::uniform_real_distribution<Real> u(-1, 1);
      for (int trial = 0; trial < 4; ++trial) {
        VecX x(p.b.size()), y(p.b.size()), bx, by;
        for (int k = 0; k < x.size(); ++k) {
          x[k] = u(rng);
          y[k] = u(rng);
        }
        mg.apply(apply, x, bx, 1);
        mg.apply(apply, y, by, 1);
        const Real xby = x.dot(by), bxy = bx.dot(y);
        EXPECT_LE(std::abs(xby - bxy), 1e-12 * bx.norm() * y.norm())
            << "constrained " << constrained << " ks " << ks;
        EXPECT_GT(x.dot(bx), 0);
        EXPECT_GT(y.dot(by), 0);
      }
    }
  }
}

// CG with the V-cycle converges to the solution of the assembled system (block-Jacobi CG to a
// tight tolerance, itself checked against CHOLMOD elsewhere), with and without contacts.
TEST(LatticeMultigrid, CgConvergesToTheSameSolution) {
  for (bool constrained : {false, true}) {
    const MgProblem p(9, 1e5, 1.0 / 60, constrained);
    VecX reference, x;
    p.cg_iterations(false, 1e-12, 1, reference);
    p.cg_iterations(true, 1e-10, 1, x);
    EXPECT_LE((x - reference).norm(), 1e-7 * reference.norm()) << constrained;
    VecX residual(p.b.size());
    p.multiply(x, residual, 1);
    EXPECT_LE((p.b - residual).norm(), 1e-10 * p.b.norm());
  }
}

// The V-cycle and CG's iterates are the same bits on 1, 2 and 3 threads.
TEST(LatticeMultigrid, SameBitsForAnyThreadCount) {
  const MgProblem p(21, 1400, 1.0 / 60, true);  // 9,261 particles: several thread ranges
  VecX first_z, first_x;
  for (int threads : {1, 2, 3}) {
    LatticeMultigrid mg;
    p.set_up(mg, threads);
    const auto apply = [&](const VecX& in, VecX& out) { p.multiply(in, out, threads); };
    VecX z, x;
    mg.apply(apply, p.b, z, threads);
    const int iterations = p.cg_iterations(true, 1e-8, threads, x);
    EXPECT_GT(iterations, 0);
    if (threads == 1) {
      first_z = z;
      first_x = x;
    } else {
      EXPECT_TRUE(z == first_z) << threads;
      EXPECT_TRUE(x == first_x) << threads;
    }
  }
}

// CG's iterations with the V-cycle do not grow with the body: at n = 40 at most 1.3 times those
// at n = 20, at the seed's stiffness and on a stiff cube (ks 1e5 at 1/60 s, where block
// Jacobi's grow with n).
TEST(LatticeMultigrid, IterationsDoNotGrowWithTheBody) {
  for (Real ks : {1400.0, 1e5}) {
    int iterations[2] = {0, 0}, jacobi[2] = {0, 0};
    const int sizes[2] = {20, 40};
    for (int k = 0; k < 2; ++k) {
      const MgProblem p(sizes[k], ks, 1.0 / 60, true);
      VecX x;
      iterations[k] = p.cg_iterations(true, 1e-5, 2, x);
      jacobi[k] = p.cg_iterations(false, 1e-5, 2, x);
    }
    std::printf(
        "ks %g: CG iterations to 1e-5, n = 20 / 40: multigrid %d / %d, block Jacobi %d / %d\n", ks,
        iterations[0], iterations[1], jacobi[0], jacobi[1]);
    EXPECT_LE(iterations[1], 1.3 * iterations[0]) << ks;
  }
}

}  // namespace
}  // namespace jelly
