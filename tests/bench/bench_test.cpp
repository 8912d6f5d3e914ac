// Tests of jelly-bench's logic: the stability search against analytic limits, the spectral
// estimate against a dense eigen-solve, the measured convergence orders, and sharding.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include <Eigen/Eigenvalues>

#include <jelly/bench/accuracy.hpp>
#include <jelly/bench/csv_io.hpp>
#include <jelly/bench/output.hpp>
#include <jelly/bench/scenes.hpp>
#include <jelly/bench/seed_table.hpp>
#include <jelly/bench/shard.hpp>
#include <jelly/bench/spectral.hpp>
#include <jelly/bench/stability.hpp>
#include <jelly/bench/stability_region.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include "support/systems.hpp"

namespace jelly::bench {
namespace {

using jelly::testing::TwoParticleSpring;

// The measured limit of the undamped two-particle spring, omega = sqrt(2 ks / m).
BracketResult two_particle_limit(const std::string& integrator, bool energy_cap) {
  // m = 1, ks = 100: omega = sqrt(200). A long rest length keeps the growing oscillation along the
  // axis (linear) until the speed bound stops it.
  TwoParticleSpring system;
  system.l0 = 100;
  BracketOptions options;
  options.dt_start = 0.01;
  options.dt_max = 1;
  return find_max_stable_dt(
      [&](Real dt) {
        SimulatorOptions o;
        o.dt = dt;
        o.output_interval = 100;
        const Model model = system.model();
        const State state = system.initial();
        // Speed bound 100 times the oscillator's speed scale omega * stretch.
        o.divergence.max_speed = 100 * system.omega0() * system.stretch;
        if (energy_cap) o.divergence.max_energy = 2 * total_energy(model, state);
        Simulator sim(model, state, make_integrator(integrator), o);
        return sim.run_until(20);
      },
      options);
}

TEST(StabilitySearch, FindsSymplecticEulerLimitOfTwoParticleSpring) {
  const Real omega = TwoParticleSpring{}.omega0();
  const BracketResult r = two_particle_limit("symplectic_euler", false);
  ASSERT_EQ(r.status, "bracketed");
  EXPECT_LE(r.dt_unstable / r.dt_stable, 1.02 + 1e-12);
  EXPECT_NEAR(r.dt_stable * omega, 2.0, 0.02 * 2.0);
  EXPECT_FALSE(r.reason.empty());
}

TEST(StabilitySearch, FindsRk4LimitOfTwoParticleSpringWithAndWithoutEnergyCap) {
  const Real omega = TwoParticleSpring{}.omega0();
  for (bool cap : {false, true}) {
    const BracketResult r = two_particle_limit("rk4", cap);
    ASSERT_EQ(r.status, "bracketed") << "energy cap " << cap;
    EXPECT_NEAR(r.dt_stable * omega, 2 * std::sqrt(2.0), 0.02 * 2 * std::sqrt(2.0))
        << "energy cap " << cap;
  }
}

TEST(StabilitySearch, ReportsStableAtEveryDtTriedAndUnstableAtMin) {
  BracketOptions o;
  o.dt_start = 1e-3;
  o.dt_max = 0.1;
  o.dt_min = 1e-5;
  RunReport ok;
  const BracketResult always = find_max_stable_dt([&](Real) { return ok; }, o);
  EXPECT_EQ(always.status, "stable_at_max");
  EXPECT_DOUBLE_EQ(always.dt_stable, 0.1);
  RunReport bad;
  bad.status = RunStatus::kDiverged;
  bad.reason = "test";
  const BracketResult never = find_max_stable_dt([&](Real) { return bad; }, o);
  EXPECT_EQ(never.status, "unstable_at_min");
  EXPECT_TRUE(std::isnan(never.dt_stable));
}

TEST(StabilityRegion, PredictsAnalyticUndampedLimits) {
  const Real rho = 400;  // omega_max = 20
  EXPECT_NEAR(predicted_max_dt("symplectic_euler", rho, 0, 1) * 20, 2.0, 1e-3);
  EXPECT_NEAR(predicted_max_dt("rk4", rho, 0, 1) * 20, 2 * std::sqrt(2.0), 1e-3);
  // Undamped oscillators are unstable for explicit Euler and midpoint at every h > 0; the
  // prediction admits growth below 1e-9 per step: |1 + i y| <= 1 + 1e-9 for y < 4.5e-5 and
  // |1 + i y - y^2 / 2| <= 1 + 1e-9 for y < 0.0095.
  EXPECT_LT(predicted_max_dt("explicit_euler", rho, 0, 1) * 20, 4.5e-5);
  EXPECT_LT(predicted_max_dt("midpoint", rho, 0, 1) * 20, 0.0095);
}

TEST(StabilityRegion, AmplificationMatchesStabilityPolynomials) {
  // Damped mode: lambda = (-c w^2 +- sqrt(c^2 w^4 - 4 w^2)) / 2.
  const Real w2 = 900, c = 0.01, h = 0.02;
  const std::complex<Real> root = std::sqrt(std::complex<Real>(c * c * w2 * w2 - 4 * w2));
  for (const std::complex<Real> lambda : {0.5 * (-c * w2 + root), 0.5 * (-c * w2 - root)}) {
    const std::complex<Real> z = h * lambda;
    // The eigenvalues of the amplification matrix are R(h lambda+) and R(h lambda-): its
    // spectral radius bounds each.
    const auto check = [&](const std::string& name, std::complex<Real> r) {
      EXPECT_LE(std::abs(r), amplification(name, h, w2, c) * (1 + 1e-9)) << name;
    };
    check("explicit_euler", 1.0 + z);
    check("midpoint", 1.0 + z + z * z / 2.0);
    check("rk4", 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0);
  }
  // The spectral radius is the larger |R| of the two modes.
  const auto rk4_r = [&](std::complex<Real> z) {
    return std::abs(1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0);
  };
  const Real expected =
      std::max(rk4_r(h * 0.5 * (-c * w2 + root)), rk4_r(h * 0.5 * (-c * w2 - root)));
  EXPECT_NEAR(amplification("rk4", h, w2, c), expected, 1e-9);
}

TEST(Spectral, StiffnessProductIsTheForceJacobianAtRest) {
  const Model model = build_cube(jelly::testing::small_cube(3));
  VecX v(model.num_dofs()), y(model.num_dofs());
  for (int i = 0; i < v.size(); ++i) v[i] = std::cos(0.9 * i);
  stiffness_product(model, v, y);
  const Real eps = 1e-6;
  const VecX zero = VecX::Zero(model.num_dofs());
  VecX fp(model.num_dofs()), fm(model.num_dofs());
  compute_forces(model, model.rest_position + eps * v, zero, fp);
  compute_forces(model, model.rest_position - eps * v, zero, fm);
  EXPECT_LT(((fp - fm) / (2 * eps) - y).norm(), 1e-6 * y.norm());
}

TEST(Spectral, RadiusMatchesDenseEigenSolveOnSmallCube) {
  CubeSpec spec;  // the seed material on a 3 x 3 x 3 cube, different coefficients per type
  spec.n = 3;
  spec.springs = {SpringCoefficients{1400, 50}, SpringCoefficients{900, 20},
                  SpringCoefficients{2000, 70}};
  Model model = build_cube(spec);
  model.mass[4] = 2.5;  // a non-uniform mass matrix
  const int dim = model.num_dofs();
  for (bool damping : {false, true}) {
    // Dense M^-1/2 (-A) M^-1/2 from the matrix-free product applied to unit vectors.
    Eigen::MatrixXd a(dim, dim);
    VecX e(dim), y(dim);
    for (int j = 0; j < dim; ++j) {
      e.setZero();
      e[j] = 1;
      damping ? damping_product(model, e, y) : stiffness_product(model, e, y);
      a.col(j) = -y;
    }
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) a(i, j) /= std::sqrt(model.mass[i / 3] * model.mass[j / 3]);
    EXPECT_LT((a - a.transpose()).norm(), 1e-9 * a.norm());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> dense(a);
    const Real exact = dense.eigenvalues()[dim - 1];
    const Real estimate = spectral_radius(model, damping);
    EXPECT_NEAR(estimate / exact, 1.0, 1e-6) << (damping ? "D" : "K");
  }
}

TEST(Accuracy, MeasuredOrdersAreOneTwoFour) {
  AccuracyOptions o;
  o.integrators = {"explicit_euler", "midpoint", "rk4", "symplectic_euler"};
  o.n = 3;
  o.t_end = 0.25;
  o.dts = {4e-4, 2e-4, 1e-4};
  o.reference_dt = 1e-5;
  o.drift_t_end = 0.1;
  const std::vector<Table> tables = run_accuracy(o);
  const Table orders = convergence_orders(tables[0], tables[1]);
  std::map<std::string, Real> expected{
      {"explicit_euler", 1}, {"midpoint", 2}, {"rk4", 4}, {"symplectic_euler", 1}};
  ASSERT_EQ(orders.rows(), 4);
  for (int r = 0; r < orders.rows(); ++r) {
    const std::string& name = orders.text(r, "integrator");
    EXPECT_EQ(orders.number(r, "points"), 3) << name;
    EXPECT_NEAR(orders.number(r, "order_finest"), expected[name], 0.2) << name;
  }
}

Table run_small_stability(const Shard& shard) {
  StabilityOptions o;
  o.integrators = {"rk4", "symplectic_euler"};
  o.ks = {1400, 4000};
  o.n = 3;
  o.horizon = 0.3;
  o.bracket.tolerance = 0.1;
  o.shard = shard;
  return run_stability(o);
}

void expect_equal_tables(const Table& a, const Table& b) {
  ASSERT_EQ(a.columns().size(), b.columns().size());
  ASSERT_EQ(a.rows(), b.rows());
  for (int r = 0; r < a.rows(); ++r)
    for (int c = 0; c < static_cast<int>(a.columns().size()); ++c)
      EXPECT_EQ(a.cell_text(r, c), b.cell_text(r, c)) << a.columns()[c].name << " row " << r;
}

TEST(Shard, MergedShardsEqualUnshardedRun) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "jelly_bench_shard_test";
  fs::remove_all(dir);
  const Table whole = run_small_stability(Shard{});
  ASSERT_EQ(whole.rows(), 8);
  std::ostringstream sink;
  for (int i = 0; i < 3; ++i) {
    const Shard shard{i, 3};
    const Table part = run_small_stability(shard);
    EXPECT_LT(part.rows(), whole.rows());
    write_outputs("stability", {part}, {}, dir.string(), shard, sink);
  }
  const MergedRun merged = merge_csv({dir.string()});
  EXPECT_EQ(merged.command, "stability");
  ASSERT_EQ(merged.tables.count("stability"), 1u);
  expect_equal_tables(merged.tables.at("stability"), whole);
  // A missing shard is an error, not a silently shorter table.
  fs::remove(dir / "stability.shard-1-of-3.csv");
  EXPECT_THROW(merge_csv({dir.string()}), InputError);
  fs::remove_all(dir);
}

TEST(Shard, ParsesAndAssignsItemsRoundRobin) {
  const Shard s = Shard::parse("1/3");
  EXPECT_TRUE(s.owns(1));
  EXPECT_TRUE(s.owns(4));
  EXPECT_FALSE(s.owns(3));
  EXPECT_EQ(s.suffix(), ".shard-1-of-3");
  EXPECT_THROW(Shard::parse("3/3"), InputError);
  EXPECT_THROW(Shard::parse("a/b"), InputError);
  EXPECT_THROW(Shard::parse("1"), InputError);
}

TEST(Csv, RoundTripsNumbersAndQuotedText) {
  Table t("t", "a test, with a comma", {"item", "name:s", "value"});
  t.add_row({0.0, std::string("a,\"b\""), 0.1 + 0.2});
  t.add_row({1.0, std::string("plain"), NAN});
  EXPECT_THROW(t.add_row({1.0, 2.0, 3.0}), std::invalid_argument);
  const std::string path = (std::filesystem::temp_directory_path() / "jelly_bench_t.csv").string();
  write_csv(path, t, {{"cpu", "test"}});
  Metadata meta;
  const Table back = read_csv(path, &meta);
  EXPECT_EQ(meta["cpu"], "test");
  EXPECT_EQ(back.description(), t.description());
  expect_equal_tables(back, t);
  EXPECT_EQ(back.number(0, "value"), 0.1 + 0.2);
  std::filesystem::remove(path);
}

TEST(Scenes, ElevatorCapAllowsThePlatformWorkAndGuardUsesIt) {
  SceneSpec slope, elevator;
  slope.n = elevator.n = 3;
  elevator.name = "elevator";
  const SceneParts a = build_scene(slope), b = build_scene(elevator);
  const Real e0 = total_energy(a.model, a.state);
  const Real cap_slope = energy_cap(a, 3, 0);
  EXPECT_NEAR(cap_slope, e0, 1e-9 * std::abs(e0));
  // 27 kg lifted by 6 m (the platform's rise over 2 s at 3 m/s^2), plus one impact at V = 6 m/s
  // of particles arriving at u = sqrt(2 g H), H = 61/9 + 4 - 1 m from the cube's top to the
  // platform's lowest point: 2 V u + 2 V^2 per kg.
  const Real mass = a.model.mass.sum();
  const Real u = std::sqrt(2 * 9.8 * (61.0 / 9 + 4 - 1));
  EXPECT_NEAR(energy_cap(b, 3, 0) - e0, mass * (9.8 * 6 + 2 * 6 * u + 2 * 6 * 6),
              1e-3 * mass * (9.8 * 6 + 2 * 6 * u));  // sampled at 1 ms
  DivergenceGuard guard;
  guard.max_energy = e0 - 1;
  EXPECT_TRUE(guard.check(a.model, a.state).has_value());
  EXPECT_FALSE(guard.check(a.state).has_value());
  guard.max_energy = e0 + 1;
  EXPECT_FALSE(guard.check(a.model, a.state).has_value());
}

TEST(Scenes, SimulatorStopsOnTheEnergyCap) {
  SceneSpec spec;
  spec.n = 3;
  spec.name = "free";
  SceneParts parts = build_scene(spec);
  SimulatorOptions options;
  options.dt = 1e-3;
  // Without gravity the energy is >= 0: a negative cap stops the run at the first check.
  options.divergence.max_energy = -1;
  Simulator capped(parts.model, parts.state, make_integrator("rk4"), options);
  const RunReport stopped = capped.run_until(1);
  EXPECT_EQ(stopped.status, RunStatus::kDiverged);
  EXPECT_EQ(stopped.steps, 1);
  EXPECT_NE(stopped.reason.find("energy"), std::string::npos) << stopped.reason;
  // The free jelly is damped: under the documented cap it completes.
  Simulator normal = make_scene_simulator(spec, "rk4", 1e-3, 1, 1);
  EXPECT_TRUE(normal.run_until(1).ok());
}

TEST(SeedTable, ClaimsHaveVerdictsForEveryScene) {
  SeedOptions o;
  o.n = 3;
  o.horizon = 0.05;
  const Table seed = run_seed(o);
  const Table claims = seed_claims(seed);
  ASSERT_EQ(claims.rows(), 12);  // 3 claims x 2 scenes x 2 placements of the contact rules
  for (int r = 0; r < claims.rows(); ++r) {
    const std::string& v = claims.text(r, "verdict");
    EXPECT_TRUE(v == "confirmed" || v == "refuted") << v;
  }
  // Without the RK4 runs the verdicts cannot be given.
  o.integrators = {"explicit_euler"};
  const Table partial = seed_claims(run_seed(o));
  for (int r = 0; r < partial.rows(); ++r) EXPECT_EQ(partial.text(r, "verdict"), "incomplete");
}

}  // namespace
}  // namespace jelly::bench
