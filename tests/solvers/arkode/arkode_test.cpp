#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>

#include <Eigen/Dense>

#include <jelly/core/detail/jacobian.hpp>
#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/arkode/detail/arkode_dirk.hpp>
#include <jelly/solvers/arkode/detail/arkode_erk.hpp>
#include <jelly/solvers/arkode/detail/arkode_iterative.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::TwoParticleSpring;

Simulator make_arkode_sim(const Model& model, const State& state, const std::string& name,
                          const ArkodeOptions& arkode, Real dt) {
  IntegratorOptions options;
  options.arkode = arkode;
  SimulatorOptions sim;
  sim.dt = dt;
  return Simulator(model, state, make_integrator(name, options), sim);
}

class EveryArkode : public ::testing::TestWithParam<std::string> {};
INSTANTIATE_TEST_SUITE_P(Arkode, EveryArkode, ::testing::Values("arkode_dirk", "arkode_erk"),
                         [](const auto& p) { return p.param; });

struct ArkodeRun {
  Real error = 0;
  Statistics stats;
};

// The damped two-particle spring against its analytic solution, contact interval 0.1 s.
ArkodeRun oscillator_run(const std::string& name, Real rtol,
                         const std::string& linear_solver = "schur") {
  TwoParticleSpring sys;
  sys.kd = 2;
  ArkodeOptions o;
  o.rtol = rtol;
  o.atol = rtol * 1e-2;         // |x| ~ 1 m, |v| ~ 1 m/s: the relative test dominates
  if (name == "arkode_dirk") {  // (arkode_erk solves nothing: it refuses a linear solver)
    o.linear_solver = value_of(arkode_linear_solvers(), linear_solver, "linear_solver");
  }
  Simulator sim = make_arkode_sim(sys.model(), sys.initial(), name, o, 0.1);
  EXPECT_TRUE(sim.run_until(2.0).ok());
  const State& s = sim.state();
  const Real length = s.x[3] - s.x[0];
  const Real rate = s.v[3] - s.v[0];
  return {std::hypot(length - sys.length(s.t), (rate - sys.length_rate(s.t)) / sys.omega0()),
          sim.integrator().statistics()};
}

// The global error falls with the tolerance, roughly in proportion, and the work grows.
TEST_P(EveryArkode, ErrorFallsWithTolerance) {
  std::vector<ArkodeRun> runs;
  const std::vector<Real> tolerances{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
  for (Real rtol : tolerances) runs.push_back(oscillator_run(GetParam(), rtol));
  for (size_t i = 0; i < runs.size(); ++i) {
    std::cout << GetParam() << " rtol " << tolerances[i] << " error " << runs[i].error << " steps "
              << runs[i].stats.at("arkode_steps") << "\n";
    // Within two decades of the tolerance (global error accumulates local ones).
    EXPECT_LT(runs[i].error, 100 * tolerances[i]);
    EXPECT_GT(runs[i].error, 1e-3 * tolerances[i]);
    if (i == 0) continue;
    EXPECT_LT(runs[i].error, runs[i - 1].error);
    EXPECT_GT(runs[i].stats.at("arkode_steps"), runs[i - 1].stats.at("arkode_steps"));
  }
  // Over five decades of tolerance the error falls by three to seven decades.
  const Real decades = std::log10(runs.front().error / runs.back().error);
  EXPECT_GT(decades, 3.0);
  EXPECT_LT(decades, 7.0);
}

// ARKODE's counters are reported and consistent.
TEST_P(EveryArkode, StatisticsAreConsistent) {
  const ArkodeRun run = oscillator_run(GetParam(), 1e-6);
  const Statistics& s = run.stats;
  EXPECT_EQ(s.at("steps"), 20);  // contact intervals of 0.1 s over 2 s
  EXPECT_GT(s.at("arkode_steps"), 20);
  EXPECT_GE(s.at("arkode_step_attempts"), s.at("arkode_steps"));
  EXPECT_EQ(s.at("arkode_step_attempts"),
            s.at("arkode_steps") + s.at("arkode_error_test_failures") +
                (GetParam() == "arkode_dirk" ? s.at("newton_convergence_failures") : 0.0));
  EXPECT_EQ(s.at("arkode_resets"), 0);  // no contact: one continuous integration
  if (GetParam() == "arkode_erk") {
    const ArkodeErk erk;
    EXPECT_EQ(erk.stages(), 7);
    EXPECT_EQ(erk.order(), 5);
    // Dormand-Prince is first-same-as-last: ERKStep reuses the last stage of a step as the
    // first of the next, so an attempt costs stages - 1 evaluations, plus a few at the start.
    EXPECT_GE(s.at("rhs_evaluations"), (erk.stages() - 1) * s.at("arkode_step_attempts"));
    EXPECT_LE(s.at("rhs_evaluations"), erk.stages() * s.at("arkode_step_attempts") + 4);
  } else {
    // Each implicit stage needs at least one Newton iteration, each a right-hand side.
    EXPECT_GE(s.at("newton_iterations"), s.at("arkode_steps"));
    EXPECT_GE(s.at("rhs_evaluations"), s.at("newton_iterations"));
    EXPECT_GT(s.at("linear_setups"), 0);
    EXPECT_EQ(s.at("schur_factorizations"), s.at("linear_setups"));
    EXPECT_EQ(s.at("schur_not_positive_definite"), 0);
  }
}

// The same problem integrated with one contact interval or many gives the same answer: without
// contact nothing restarts ARKODE. A state changed from outside restarts it.
TEST_P(EveryArkode, ContinuesAcrossIntervalsAndRestartsOnChangedState) {
  TwoParticleSpring sys;
  sys.kd = 2;
  ArkodeOptions o;
  Simulator one = make_arkode_sim(sys.model(), sys.initial(), GetParam(), o, 1.0);
  Simulator many = make_arkode_sim(sys.model(), sys.initial(), GetParam(), o, 0.01);
  ASSERT_TRUE(one.run_until(1.0).ok());
  ASSERT_TRUE(many.run_until(1.0).ok());
  EXPECT_LT((one.state().x - many.state().x).norm(), 1e-5);
  EXPECT_EQ(many.integrator().statistics().at("arkode_resets"), 0);
  State kicked = many.state();
  kicked.v[0] += 0.1;
  many.set_state(kicked);
  ASSERT_TRUE(many.run_until(1.5).ok());
  EXPECT_EQ(many.integrator().statistics().at("arkode_resets"), 1);
}

// A spinning cube of stiff springs (ks = 1e5): the explicit method is held to its stability
// limit, the L-stable DIRK follows the slow rotation.
TEST(Arkode, StiffSpringsDirkTakesTenTimesFewerSteps) {
  CubeSpec spec = testing::small_cube(3);
  for (auto& c : spec.springs) c = {1e5, 50};
  spec.gravity.setZero();
  const Model model = build_cube(spec);
  State s0 = rest_state(model);
  const Vec3 c = center_of_mass(model, s0);
  const Vec3 omega(0, 2, 0);
  for (int i = 0; i < model.num_particles(); ++i)
    particle(s0.v, i) = omega.cross(Vec3(particle(s0.x, i)) - c);
  double steps[2];
  Vec3 com[2];
  int k = 0;
  for (const std::string name : {"arkode_dirk", "arkode_erk"}) {
    ArkodeOptions o;
    o.rtol = 1e-5;
    o.atol = 1e-7;
    Simulator sim = make_arkode_sim(model, s0, name, o, 0.1);
    ASSERT_TRUE(sim.run_until(2.0).ok()) << name;
    steps[k] = sim.integrator().statistics().at("arkode_steps");
    com[k] = center_of_mass(model, sim.state());
    std::cout << name << " steps " << steps[k] << "\n";
    ++k;
  }
  EXPECT_LT(10 * steps[0], steps[1]);
  EXPECT_LT((com[0] - com[1]).norm(), 1e-5);
}

// The two linear solvers of arkode_dirk solve the same Newton systems.
TEST(Arkode, KluAndSchurAgree) {
  const ArkodeRun schur = oscillator_run("arkode_dirk", 1e-7, "schur");
  const ArkodeRun klu = oscillator_run("arkode_dirk", 1e-7, "klu");
  EXPECT_LT(schur.error, 1e-6);
  EXPECT_LT(klu.error, 1e-6);
  EXPECT_NEAR(schur.stats.at("arkode_steps"), klu.stats.at("arkode_steps"),
              0.1 * schur.stats.at("arkode_steps"));
  EXPECT_GT(klu.stats.at("jacobian_evaluations"), 0);
}

// Every linear solver of arkode_dirk (the iterative ones included) solves the same Newton
// systems: the same error and nearly the same steps as the direct Schur solve (block Jacobi
// alone is a modified Newton: more Newton failures, more steps).
TEST(Arkode, EveryLinearSolverAgreesWithSchur) {
  const ArkodeRun schur = oscillator_run("arkode_dirk", 1e-7, "schur");
  for (const std::string solver : {"cg", "gmres", "jacobi", "auto"}) {
    const ArkodeRun run = oscillator_run("arkode_dirk", 1e-7, solver);
    EXPECT_LT(run.error, 1e-6) << solver;
    if (solver == "jacobi") {
      EXPECT_LT(run.stats.at("arkode_steps"), 2 * schur.stats.at("arkode_steps"));
      continue;
    }
    EXPECT_NEAR(run.stats.at("arkode_steps"), schur.stats.at("arkode_steps"),
                0.1 * schur.stats.at("arkode_steps"))
        << solver;
  }
  const ArkodeRun cg = oscillator_run("arkode_dirk", 1e-7, "cg");
  EXPECT_GT(cg.stats.at("cg_iterations"), 0);
  EXPECT_EQ(cg.stats.count("schur_factorizations"), 0u);
  const ArkodeRun gmres = oscillator_run("arkode_dirk", 1e-7, "gmres");
  EXPECT_GT(gmres.stats.at("krylov_iterations"), 0);
  // "auto" is the matrix-free CG (docs/arkode.md).
  const ArkodeRun automatic = oscillator_run("arkode_dirk", 1e-7, "auto");
  EXPECT_EQ(automatic.stats.count("cg_iterations"), 1u);
}

// A particle on a damped spring hanging from a pinned particle (no gravity): x1(t) is the
// one-mass oscillator's, omega0^2 = ks / m, decay kd / (2 m). The iterative Newton solves
// prescribe the pinned particle's velocity change, so ARKODE keeps it where the pin holds it and
// nothing restarts ARKODE (before, every interval restarted it: the pinned particle had moved
// within the Newton tolerance and the Simulator put it back).
TEST(Arkode, DirkHonoursPinsInsideItsNewtonSolves) {
  TwoParticleSpring sys;
  sys.kd = 2;
  const Real m = sys.m, ks = sys.ks, kd = sys.kd, l0 = sys.l0, stretch = sys.stretch;
  Model model = sys.model();
  model.pins.add_fixed(0, Vec3::Zero());
  State s = rest_state(model);
  s.x[3] = l0 + stretch;
  const Real g = kd / (2 * m), w = std::sqrt(ks / m - g * g);
  for (const std::string solver : {"cg", "jacobi", "gmres"}) {
    SCOPED_TRACE(solver);
    ArkodeOptions o;
    o.linear_solver = value_of(arkode_linear_solvers(), solver, "linear_solver");
    Simulator sim = make_arkode_sim(model, s, "arkode_dirk", o, 0.05);
    ASSERT_TRUE(sim.run_until(2.0).ok());
    const Real t = sim.state().t;
    const Real expected =
        l0 + stretch * std::exp(-g * t) * (std::cos(w * t) + g / w * std::sin(w * t));
    EXPECT_NEAR(sim.state().x[3], expected, 1e-5);
    EXPECT_EQ(Vec3(particle(sim.state().x, 0)), Vec3::Zero());
    const Statistics stats = sim.integrator().statistics();
    EXPECT_EQ(stats.at("arkode_resets"), 0);
    EXPECT_EQ(stats.at("newton_convergence_failures"), 0);
  }
}

// A mass hanging on a spring from a pin that a path shakes sideways (5 cm at 1 Hz), from rest
// (the path's initial velocity is not the state's): ARKODE starts the pinned particle on its path
// and keeps it there within its error test (or restarts from the path), so the hanging mass
// follows RK4's trajectory at a small step, for every linear solver and the ERK.
TEST(Arkode, DrivenPinsStayOnTheirPathsInsideArkode) {
  Model model;
  model.mass = VecX::Constant(2, 1.0);
  model.rest_position = VecX::Zero(6);
  model.rest_position[4] = -1;
  model.springs.add(0, 1, 1.0, {100, 1}, SpringType::kStructural);
  model.pins.add(0, Vec3::Zero(), model.pins.add_path(Path::oscillation(Vec3(0.05, 0, 0), 1.0)));
  const State s0 = rest_state(model);
  IntegratorOptions rk4;
  Simulator reference(model, s0, make_integrator("rk4", rk4), SimulatorOptions{1e-4, 0, {}});
  ASSERT_TRUE(reference.run_until(3.0).ok());
  const Vec3 expected = particle(reference.state().x, 1);
  for (const auto& [name, solver] :
       {std::pair{"arkode_dirk", "cg"}, std::pair{"arkode_dirk", "schur"},
        std::pair{"arkode_dirk", "klu"}, std::pair{"arkode_erk", "auto"}}) {
    SCOPED_TRACE(std::string(name) + " " + solver);
    ArkodeOptions o;
    o.linear_solver = value_of(arkode_linear_solvers(), solver, "linear_solver");
    Simulator sim = make_arkode_sim(model, s0, name, o, 1.0 / 60);
    ASSERT_TRUE(sim.run_until(3.0).ok());
    // Measured: 1.2e-8 to 8e-8 m (schur, klu, erk), 8e-6 m (cg: its inexact Newton stops at
    // ARKODE's tolerance); 0.9 m when ARKODE kept the pinned particle's initial velocity (0
    // instead of the path's 0.31 m/s).
    EXPECT_LT((Vec3(particle(sim.state().x, 1)) - expected).norm(), 2e-5);
    EXPECT_TRUE(sim.integrator().statistics().count("arkode_pin_drift"));
  }
}

// A particle falling in wind of drag c (N s/m) and air velocity w: m v' = m g + c (w - v), so
// v(t) = v_inf (1 - exp(-c t / m)) from rest, terminal velocity v_inf = w + m g / c. With a
// stiff drag (c / m = 1000 1/s) and 1/60 s intervals the DIRK's steps are far longer than the
// drag's time constant: Newton converges only with the drag in its matrix (without it each
// iteration amplified the error by about gamma c / m).
TEST(Arkode, DirkReachesTheWindsTerminalVelocity) {
  const Real m = 0.01, c = 10;
  Model model;
  model.mass = VecX::Constant(1, m);
  model.rest_position = VecX::Zero(3);
  ExternalForce wind;
  wind.kind = ExternalForceKind::kWind;
  wind.particles = {0};
  wind.vector = Vec3(3, 0, 0);
  wind.drag = c;
  model.external_forces = {wind};
  const Vec3 terminal = wind.vector + m * model.gravity / c;
  for (const std::string solver : {"cg", "jacobi", "gmres"}) {
    SCOPED_TRACE(solver);
    ArkodeOptions o;
    o.linear_solver = value_of(arkode_linear_solvers(), solver, "linear_solver");
    Simulator sim = make_arkode_sim(model, rest_state(model), "arkode_dirk", o, 1.0 / 60);
    ASSERT_TRUE(sim.run_until(1.0).ok());
    const Real t = sim.state().t;
    const Vec3 expected = terminal * (1 - std::exp(-c * t / m));
    EXPECT_LT((Vec3(particle(sim.state().v, 0)) - expected).norm(), 1e-6 * terminal.norm());
    const Statistics stats = sim.integrator().statistics();
    EXPECT_EQ(stats.at("newton_convergence_failures"), 0);
    EXPECT_LT(stats.at("arkode_steps"), 200);
  }
}

// The matrix-free operator of the iterative solvers against dense matrices assembled by
// SpringJacobian: S = M - g D - g^2 K, K p, the filtered operator of a seed contact and the
// block-Jacobi solves.
TEST(Arkode, SpringOperatorMatchesDenseMatrices) {
  using Dense = Eigen::MatrixXd;
  CubeSpec spec = testing::small_cube(3);
  spec.particle_mass = 1.5;
  const Model model = build_cube(spec);
  State s = rest_state(model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) {
    s.x[i] += 0.05 * u(rng);
    s.v[i] = u(rng);
  }
  const int n = model.num_dofs();
  SpringJacobian jacobian(model);
  SparseMatrix ks = jacobian.make_matrix(), ds = jacobian.make_matrix();
  jacobian.assemble(model, s.x, s.v, JacobianOptions{}, ks, ds);
  const Dense k(ks), d(ds);
  const Real g = 0.01;
  Dense m = Dense::Zero(n, n);
  for (int i = 0; i < n; ++i) m(i, i) = model.mass[i / 3];
  const Dense full = m - g * d - g * g * k;

  arkode::SpringOperator op;
  op.linearize(model, s.x, s.v);
  op.set_gamma(model, g);
  VecX p(n), out;
  for (int i = 0; i < n; ++i) p[i] = u(rng);
  op.multiply_s(model, p, out);
  EXPECT_LT((out - full * p).norm(), 1e-12 * (full * p).norm());
  op.multiply_k(model, p.data(), out);
  EXPECT_LT((out - k * p).norm(), 1e-12 * (k * p).norm());

  // Block Jacobi: each particle's 6x6 block of I - g J solved exactly.
  VecX r(2 * n), z(2 * n);
  for (int i = 0; i < 2 * n; ++i) r[i] = u(rng);
  op.block_jacobi(model, r.data(), z.data());
  for (int i = 0; i < model.num_particles(); ++i) {
    Dense block = Dense::Identity(6, 6);
    block.block(0, 3, 3, 3) = -g * Dense::Identity(3, 3);
    block.block(3, 0, 3, 3) = -g * k.block(3 * i, 3 * i, 3, 3) / model.mass[i];
    block.block(3, 3, 3, 3) -= g * d.block(3 * i, 3 * i, 3, 3) / model.mass[i];
    Eigen::VectorXd ri(6), zi(6);
    ri << r.segment<3>(3 * i), r.segment<3>(n + 3 * i);
    zi << z.segment<3>(3 * i), z.segment<3>(n + 3 * i);
    EXPECT_LT((block * zi - ri).norm(), 1e-12 * ri.norm()) << "particle " << i;
  }

  // A seed contact on particle 4 with normal nn and friction damping c: (P (S + G) P + I - P).
  const Vec3 nn = Vec3(1, 2, 2) / 3;
  const Real c = 20;
  op.set_constraints({{4, nn, c}});
  op.set_gamma(model, g);
  Dense filter = Dense::Identity(n, n), friction = Dense::Zero(n, n);
  filter.block(12, 12, 3, 3) -= nn * nn.transpose();
  friction.block(12, 12, 3, 3) = g * c * (Eigen::Matrix3d::Identity() - nn * nn.transpose());
  const Dense filtered = filter * (full + friction) * filter + (Dense::Identity(n, n) - filter);
  op.multiply_filtered(model, p, out);
  EXPECT_LT((out - filtered * p).norm(), 1e-12 * (filtered * p).norm());
  // Its preconditioner inverts the filtered operator's diagonal blocks.
  op.precondition(p, out);
  for (int i = 0; i < model.num_particles(); ++i) {
    const Eigen::Vector3d back = filtered.block(3 * i, 3 * i, 3, 3) * out.segment<3>(3 * i);
    EXPECT_LT((back - p.segment<3>(3 * i)).norm(), 1e-12 * p.segment<3>(3 * i).norm());
  }
}

void expect_input_error(const std::string& name, const ArkodeOptions& o, const std::string& field) {
  IntegratorOptions options;
  options.arkode = o;
  try {
    make_integrator(name, options);
    ADD_FAILURE() << "no InputError for " << field;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(Arkode, BadOptionsNameTheField) {
  const auto with = [](auto change) {
    ArkodeOptions o;
    change(o);
    return o;
  };
  for (const std::string name : {"arkode_dirk", "arkode_erk"}) {
    expect_input_error(name, with([](auto& o) { o.rtol = 0; }), "integrator.options.rtol");
    expect_input_error(name, with([](auto& o) { o.rtol = 1; }), "integrator.options.rtol");
    expect_input_error(name, with([](auto& o) { o.atol = -1; }), "integrator.options.atol");
    expect_input_error(name, with([](auto& o) { o.max_step = -1; }), "integrator.options.max_step");
    expect_input_error(name, with([](auto& o) { o.max_steps = 0; }),
                       "integrator.options.max_steps");
    expect_input_error(name, with([](auto& o) { o.method = "ARKODE_NO_SUCH_TABLE"; }),
                       "integrator.options.method");
  }
  // A table of the other kind, and one without an embedding (no error estimate).
  expect_input_error("arkode_erk", with([](auto& o) { o.method = "ARKODE_SDIRK_5_3_4"; }),
                     "integrator.options.method");
  expect_input_error("arkode_dirk", with([](auto& o) { o.method = "ARKODE_DORMAND_PRINCE_7_4_5"; }),
                     "integrator.options.method");
  expect_input_error("arkode_erk", with([](auto& o) { o.method = "ARKODE_KNOTH_WOLKE_3_3"; }),
                     "integrator.options.method");
  // Other tables are accepted and set the order.
  ArkodeOptions o;
  o.method = "ARKODE_BOGACKI_SHAMPINE_4_2_3";
  EXPECT_EQ(ArkodeErk(o).order(), 3);
  o.method = "ARKODE_SDIRK_5_3_4";
  EXPECT_EQ(ArkodeDirk(o).order(), 4);
}

// The named choices are tables (core/errors.hpp): every method of the tables builds its
// integrator with the order its name ends with, an unknown name is refused with the table's
// names, and the scene's linear_solver is read and written through its table (default "auto").
TEST(Arkode, MethodsAndLinearSolversAreTables) {
  for (const auto& [table, name] : {std::pair{&arkode_erk_methods(), "arkode_erk"},
                                    std::pair{&arkode_dirk_methods(), "arkode_dirk"}}) {
    for (const EnumName<int>& method : *table) {
      SCOPED_TRACE(method.name);
      IntegratorOptions options;
      options.arkode.method = std::string(method.name);
      const auto integrator = make_integrator(name, options);
      EXPECT_EQ(integrator->order(), method.name.back() - '0');
    }
  }
  IntegratorOptions options;
  options.arkode.method = "ARKODE_NO_SUCH_TABLE";
  try {
    make_integrator("arkode_dirk", options);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("integrator.options.method = \"ARKODE_NO_SUCH_TABLE\" is "
                                         "invalid: one of \"ARKODE_SDIRK_2_1_2\", "),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(ArkodeOptions{}.linear_solver, ArkodeLinearSolver::kAuto);
  EXPECT_EQ(ArkodeOptions{}.to_json()["linear_solver"], "auto");
  for (const EnumName<ArkodeLinearSolver>& solver : arkode_linear_solvers()) {
    Json table_options = Json::object();
    table_options["linear_solver"] = std::string(solver.name);
    JsonFields fields(table_options, "integrator.options");
    EXPECT_EQ(ArkodeOptions::read(fields).linear_solver, solver.value);
  }
  Json bad = Json::object();
  bad["linear_solver"] = "lu";
  JsonFields fields(bad, "integrator.options");
  try {
    ArkodeOptions::read(fields);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("integrator.options.linear_solver = \"lu\" is invalid: "
                                         "one of \"auto\", \"cg\", \"jacobi\", \"gmres\", "
                                         "\"schur\", \"klu\""),
              std::string::npos)
        << e.what();
  }
}

// A failure inside ARKODE is a returned status with SUNDIALS' flag name and message.
TEST_P(EveryArkode, TooMuchWorkIsAFailureWithSundialsMessage) {
  TwoParticleSpring sys;
  ArkodeOptions o;
  o.max_steps = 3;
  Simulator sim = make_arkode_sim(sys.model(), sys.initial(), GetParam(), o, 1.0);
  const RunReport report = sim.run_until(1.0);
  EXPECT_EQ(report.status, RunStatus::kSolverFailed);
  EXPECT_NE(report.reason.find("ARK_TOO_MUCH_WORK"), std::string::npos) << report.reason;
  EXPECT_NE(report.reason.find("mxstep"), std::string::npos) << report.reason;
}

// The seed cube (n = 10) on the 20 degree slope and on the elevator, default contact: no
// divergence, never more than 1 cm into the terrain. The full 5 s runs from the seed pose are
// in docs/arkode.md (bench/arkode_bench); here the cube starts lowered so that 0.4 s includes
// the landing, and arkode_dirk runs at rtol 1e-4 (each contact interval restarts its 7-stage
// Newton iterations on 3000 unknowns: seconds per simulated 0.1 s at the default 1e-6).
struct SeedScene {
  std::string integrator;
  Real dt;
  bool elevator;
};
// Without it GoogleTest prints the parameter's bytes, padding included (valgrind: uninitialised).
void PrintTo(const SeedScene& scene, std::ostream* out) {
  *out << scene.integrator << (scene.elevator ? " elevator" : " slope") << " dt " << scene.dt;
}
class ArkodeSeedScenes : public ::testing::TestWithParam<SeedScene> {};
INSTANTIATE_TEST_SUITE_P(Arkode, ArkodeSeedScenes,
                         ::testing::Values(SeedScene{"arkode_erk", 1e-3, false},
                                           SeedScene{"arkode_erk", 1e-3, true},
                                           SeedScene{"arkode_dirk", 1.0 / 60, false},
                                           SeedScene{"arkode_dirk", 1.0 / 60, true}),
                         [](const auto& p) {
                           return p.param.integrator + (p.param.elevator ? "_elevator" : "_slope");
                         });

TEST_P(ArkodeSeedScenes, RunsWithoutDivergence) {
  const SeedScene& scene = GetParam();
  const Model model = build_cube(CubeSpec{});
  State s0 = rest_state(model);
  // Lowered so that the bottom face lands after about 0.3 s.
  const Real lowered = scene.elevator ? 5.3 : 5.5;
  for (int i = 0; i < model.num_particles(); ++i) particle(s0.x, i).y() -= lowered;
  SimulatorOptions options;
  options.dt = scene.dt;
  options.output_interval = 1.0 / 60;
  IntegratorOptions integrator;
  if (scene.integrator == "arkode_dirk") {
    integrator.arkode.rtol = 1e-4;
    integrator.arkode.atol = 1e-6;
  }
  Simulator sim(model, s0, make_integrator(scene.integrator, integrator), options);
  if (scene.elevator) {
    sim.add_terrain(std::make_unique<Elevator>());
  } else {
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
  }
  const Terrain& terrain = *sim.terrains()[0];
  Real deepest = 0;
  testing::Probe probe([&](const Simulator& s) {
    for (int i = 0; i < model.num_particles(); ++i)
      deepest = std::min(deepest, terrain.signed_distance(particle(s.state().x, i), s.state().t));
  });
  sim.add_observer(probe);
  const RunReport report = sim.run_until(0.4);
  ASSERT_TRUE(report.ok()) << report.brief() << " " << report.reason;
  std::cout << scene.integrator << " " << report.brief() << " deepest " << deepest << "\n";
  EXPECT_GT(deepest, -0.01);
  EXPECT_GT(report.statistics.at("arkode_resets"), 0);  // it did land
}

}  // namespace
}  // namespace jelly
