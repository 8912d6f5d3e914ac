#include <jelly/solvers/linear/detail/smoothed_aggregation.hpp>

#include <gtest/gtest.h>

#include <random>

#include <jelly/core/detail/jacobian.hpp>
#include <jelly/geometry/detail/cloth.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {
namespace {

// A box of c x c x c cubic cells of edge `edge` / c, each cut into 6 tetrahedra around its
// diagonal (neighbouring cells' faces agree): a tet mesh that is not a lattice body.
TetMesh tet_box(int c, Real edge) {
  TetMesh mesh;
  const auto id = [c](int i, int j, int k) { return (i * (c + 1) + j) * (c + 1) + k; };
  for (int i = 0; i <= c; ++i)
    for (int j = 0; j <= c; ++j)
      for (int k = 0; k <= c; ++k) mesh.vertices.push_back(Vec3(i, j, k) * (edge / c));
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int i = 0; i < c; ++i)
    for (int j = 0; j < c; ++j)
      for (int k = 0; k < c; ++k)
        for (const auto& p : perms) {
          int at[3] = {0, 0, 0};
          Tet t;
          t[0] = id(i, j, k);
          for (int s = 0; s < 3; ++s) {
            ++at[p[s]];
            t[s + 1] = id(i + at[0], j + at[1], k + at[2]);
          }
          mesh.tets.push_back(t);
        }
  return mesh;
}

// A soft tet box of edge 0.4 m (density 1000 kg/m^3); ks scaled with the cell size so that the
// material is the same at every refinement.
Model tet_model(int cells, Real ks_per_metre = 4000, Vec3 origin = Vec3::Zero()) {
  Material material;
  const Real h = 0.4 / cells;
  material.springs.fill({ks_per_metre * h, 0.5 * ks_per_metre * h * 0.01});
  material.density = 1000;
  Pose pose;
  pose.position = origin;
  Model m;
  m.add_body("tets", build_tetmesh(tet_box(cells, 0.4), pose, material, "t."));
  return m;
}

Model cloth_model(int n) {
  ClothShape cloth;
  cloth.nu = cloth.nv = n;
  cloth.size_u = cloth.size_v = 1;
  cloth.pose.position = Vec3(0, 1, 0);
  Material material;
  material.density = 0.3;
  material.springs = {SpringCoefficients{60, 0.05}, SpringCoefficients{20, 0.02},
                      SpringCoefficients{2, 0.002}};
  Model m;
  m.add_body("cloth", cloth.build(material, "c."));
  return m;
}

// The backward-Euler matrix at dt 1/60 of `model` deformed randomly by about 1 % of a cell
// (positions in x), filtered as the implicit step filters it (ImplicitContact::constrain):
// particles in `pinned` get identity rows, those in `sliding` (normal +y) S A S + n n^T with
// S = I - n n^T.
SparseMatrix filtered(const Model& model, const std::vector<int>& pinned,
                      const std::vector<int>& sliding, VecX& x) {
  SpringJacobian jacobian(model);
  SparseMatrix original = jacobian.make_matrix();
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  x = model.rest_position;
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += 0.0005 * u(rng);
  const VecX v = VecX::Zero(x.size());
  VecX kw(x.size());
  const Real h = 1.0 / 60;
  jacobian.assemble_system(model, x, v, JacobianOptions{}, h, h * h, original, v, kw);
  SparseMatrix a = original;
  const int np = model.num_particles();
  std::vector<Mat3> s(np, Mat3::Identity());
  for (int p : pinned) s[p].setZero();
  const Vec3 n(0, 1, 0);
  for (int p : sliding) s[p] = Mat3::Identity() - n * n.transpose();
  for (int j = 0; j < a.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(a, j); it; ++it) {
      const int bi = static_cast<int>(it.row()) / 3, bj = j / 3;
      const int ri = static_cast<int>(it.row()) % 3, cj = j % 3;
      Real value = 0;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q)
          value += s[bi](ri, p) * original.coeff(3 * bi + p, 3 * bj + q) * s[bj](q, cj);
      if (bi == bj) value += (Mat3::Identity() - s[bi])(ri, cj);
      it.valueRef() = value;
    }
  return a;
}

// The cycle B (the W-cycle and the V-cycle of amg_cycle) is a symmetric positive definite
// operator: u^T B w = w^T B u and w^T B w > 0 on random vectors, with pinned particles and
// sliding contacts filtered into the matrix, on a tet body and on a cloth; and B r is the same
// bits on 1, 2 and 3 threads.
TEST(SmoothedAggregation, IsSymmetricPositiveDefiniteWithPinsAndContacts) {
  for (const bool cloth : {false, true})
    for (const SmoothedAggregation::Options cycle :
         {SmoothedAggregation::Options{}, SmoothedAggregation::Options{2, 2, false}}) {
      const Model model = cloth ? cloth_model(40) : tet_model(12);
      const int np = model.num_particles();
      std::vector<int> pinned, sliding;
      for (int i = 0; i < np; i += 37) pinned.push_back(i);
      for (int i = 5; i < np; i += 11) sliding.push_back(i);
      VecX x;
      const SparseMatrix a = filtered(model, pinned, sliding, x);
      SmoothedAggregation amg(cycle);
      ASSERT_TRUE(amg.setup(a, x, 1).ok());
      EXPECT_GE(amg.levels(), 2) << (cloth ? "cloth" : "tets");
      std::mt19937 rng(11);
      std::normal_distribution<Real> g;
      const int n = static_cast<int>(a.rows());
      VecX u(n), w(n), bu(n), bw(n);
      for (int trial = 0; trial < 10; ++trial) {
        for (int i = 0; i < n; ++i) {
          u[i] = g(rng);
          w[i] = g(rng);
        }
        amg.apply(u, bu, 1);
        amg.apply(w, bw, 1);
        const Real scale = u.norm() * bw.norm();
        EXPECT_NEAR(u.dot(bw), w.dot(bu), 1e-12 * scale);
        EXPECT_GT(w.dot(bw), 0);
        EXPECT_GT(u.dot(bu), 0);
      }
      for (const int threads : {2, 3}) {
        SmoothedAggregation other(cycle);
        ASSERT_TRUE(other.setup(a, x, threads).ok());
        VecX bu_t(n);
        other.apply(u, bu_t, threads);
        EXPECT_TRUE(bu_t == bu) << threads << " threads";
      }
    }
}

// CG iterations to 1e-8 from zero on the tet box's system (stiff: the springs dominate the mass)
// at two refinements: amg's grow by at most 1.3x from 8^3 to 16^3 cells, block Jacobi's double;
// amg's V-cycle (amg_cycle "v") needs fewer than block Jacobi (its counts printed).
TEST(SmoothedAggregation, IterationsHardlyGrowWithTheBody) {
  const auto iterations = [](int cells, CgPreconditioner preconditioner, bool v_cycle = false) {
    const Model model = tet_model(cells, 4e6);
    VecX x;
    std::vector<int> pinned;
    for (int i = 0; i < model.num_particles(); ++i)
      if (model.rest_position[3 * i + 1] == 0) pinned.push_back(i);  // the bottom face
    const SparseMatrix a = filtered(model, pinned, {}, x);
    CgOptions o;
    o.preconditioner = preconditioner;
    o.tolerance = 1e-8;
    if (v_cycle) {
      o.amg_coarse_degree = 2;
      o.amg_w_cycle = false;
    }
    CgSolver cg(o);
    cg.set_coordinates(x);
    EXPECT_TRUE(cg.analyze(a).ok());
    EXPECT_TRUE(cg.factorize(a).ok());
    VecX b(a.rows());
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = std::sin(0.37 * i) + (i % 3 == 1 ? 1 : 0);
    VecX y = VecX::Zero(b.size());
    const LinearResult r = cg.solve(b, y);
    EXPECT_TRUE(r.ok()) << r.message;
    return r.iterations;
  };
  const int amg8 = iterations(8, CgPreconditioner::kAmg);
  const int amg16 = iterations(16, CgPreconditioner::kAmg);
  const int v8 = iterations(8, CgPreconditioner::kAmg, true);
  const int v16 = iterations(16, CgPreconditioner::kAmg, true);
  const int jacobi8 = iterations(8, CgPreconditioner::kJacobi);
  const int jacobi16 = iterations(16, CgPreconditioner::kJacobi);
  RecordProperty("amg_8", amg8);
  RecordProperty("amg_16", amg16);
  RecordProperty("jacobi_8", jacobi8);
  RecordProperty("jacobi_16", jacobi16);
  RecordProperty("amg_v_8", v8);
  RecordProperty("amg_v_16", v16);
  std::printf(
      "CG iterations, 8^3 / 16^3 cells: amg %d / %d, amg V-cycle %d / %d, block Jacobi "
      "%d / %d\n",
      amg8, amg16, v8, v16, jacobi8, jacobi16);
  EXPECT_LE(amg16, 1.3 * amg8);
  EXPECT_LT(amg16, jacobi16);
  EXPECT_LT(v16, jacobi16);
  EXPECT_GT(jacobi16, 1.5 * jacobi8);
}

// cg_preconditioner = "amg" in the implicit step: a tet box falling onto the slope (contacts in
// the solve) and a cloth pinned at two corners end where block-Jacobi CG ends (both to a tight
// CG tolerance), and the amg runs are the same bits on 1, 2 and 3 threads.
TEST(SmoothedAggregation, ImplicitEulerAgreesWithBlockJacobiOnAnyThreadCount) {
  for (const bool cloth : {false, true}) {
    Model model = cloth ? cloth_model(24) : tet_model(8, 4000, Vec3(-0.2, 0.05, -0.2));
    if (cloth) {
      model.pins.add_fixed(0, particle(model.rest_position, 0));
      model.pins.add_fixed(23 * 24, particle(model.rest_position, 23 * 24));
    }
    const auto run = [&](CgPreconditionerKind preconditioner, int threads, std::string* solver,
                         double* iterations) {
      IntegratorOptions o;
      o.implicit.linear_solver = ImplicitLinearSolver::kCg;
      o.implicit.cg_preconditioner = preconditioner;
      o.implicit.cg_tolerance = 1e-11;
      o.implicit.contact_screening_tolerance = 0;
      SimulatorOptions so{1.0 / 60, 0, {}};
      so.threads = threads;
      Simulator sim = Simulator(model, rest_state(model), make_integrator("implicit_euler", o), so);
      if (!cloth) sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
      const RunReport report = sim.run_until(0.5);
      EXPECT_TRUE(report.ok()) << report.reason;
      *solver =
          std::string(static_cast<const ImplicitEuler&>(sim.integrator()).linear_solver_name());
      *iterations = report.statistics.at("cg_iterations");
      if (preconditioner == CgPreconditionerKind::kAmg) {
        EXPECT_GE(report.statistics.at("multigrid_levels"), 2);
      }
      return sim.state();
    };
    std::string jacobi_name, amg_name, other_name;
    double jacobi_iterations = 0, amg_iterations = 0, other_iterations = 0;
    const State jacobi = run(CgPreconditionerKind::kJacobi, 1, &jacobi_name, &jacobi_iterations);
    const State amg = run(CgPreconditionerKind::kAmg, 1, &amg_name, &amg_iterations);
    EXPECT_EQ(amg_name, "cg_amg");
    EXPECT_LT((amg.x - jacobi.x).cwiseAbs().maxCoeff(), 1e-7) << (cloth ? "cloth" : "tets");
    EXPECT_LT((amg.v - jacobi.v).cwiseAbs().maxCoeff(), 1e-5) << (cloth ? "cloth" : "tets");
    EXPECT_LT(amg_iterations, jacobi_iterations);
    for (const int threads : {2, 3}) {
      const State other = run(CgPreconditionerKind::kAmg, threads, &other_name, &other_iterations);
      EXPECT_TRUE(other.x == amg.x) << threads << " threads";
      EXPECT_TRUE(other.v == amg.v) << threads << " threads";
      EXPECT_EQ(other_iterations, amg_iterations);
    }
  }
}

}  // namespace
}  // namespace jelly
