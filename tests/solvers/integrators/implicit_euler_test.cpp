#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <random>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/elevator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

TEST(ImplicitEuler, SimulatorReportsSolverFailure) {
  CubeSpec spec = testing::small_cube(4, 1.0);
  for (auto& c : spec.springs) c = SpringCoefficients{100000, 50};
  const Model model = build_cube(spec);
  State s = rest_state(model);
  const Vec3 c = center_of_mass(model, s);
  for (int i = 0; i < model.num_particles(); ++i)
    particle(s.x, i) = c + 0.4 * (Vec3(particle(s.x, i)) - c);
  IntegratorOptions o;
  o.implicit.definiteness = DefinitenessFix::kNone;
  o.implicit.linear_solver = ImplicitLinearSolver::kCholmod;
  SimulatorOptions so;
  so.dt = 1.0 / 30;
  Simulator sim(model, s, make_integrator("implicit_euler", o), so);
  const RunReport report = sim.run_until(1.0);
  EXPECT_EQ(report.status, RunStatus::kSolverFailed);
  EXPECT_EQ(report.steps, 0);
  EXPECT_NE(report.reason.find("CHOLMOD"), std::string::npos) << report.reason;
  EXPECT_NE(report.reason.find("not positive definite"), std::string::npos) << report.reason;
  EXPECT_EQ(sim.state().x, s.x);  // the failed step left the state alone
}

// The symbolic analysis runs once over a whole run; each step factorizes and solves once, plus
// once more for each change of the set of particles in contact.
TEST(ImplicitEuler, AnalysesThePatternOnce) {
  for (ImplicitLinearSolver backend :
       {ImplicitLinearSolver::kCholmod, ImplicitLinearSolver::kLdlt, ImplicitLinearSolver::kCg}) {
    const std::string name(name_of(implicit_linear_solvers(), backend));
    const Model model = build_cube(testing::small_cube(4, 1.0, Vec3(0, 0.3, 0)));
    IntegratorOptions o;
    o.implicit.linear_solver = backend;
    o.implicit.cg_preconditioner = CgPreconditionerKind::kCholmod;
    Simulator sim = Simulator(model, rest_state(model), make_integrator("implicit_euler", o),
                              SimulatorOptions{0.01, 0, {}});
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
    const RunReport report = sim.run_until(2.0);
    ASSERT_TRUE(report.ok()) << report.reason;
    const Statistics& st = report.statistics;
    EXPECT_EQ(st.at("steps"), 200) << name;
    EXPECT_EQ(st.at("symbolic_analyses"), 1) << name;
    const double solves = 200 + st.at("contact_extra_solves");
    EXPECT_LT(st.at("contact_extra_solves"), 20) << name;
    EXPECT_EQ(st.at("linear_solves"), solves) << name;
    EXPECT_EQ(st.at("newton_iterations"), solves) << name;
    if (backend == ImplicitLinearSolver::kCg) {
      EXPECT_GE(st.at("numeric_factorizations"), 1);
      EXPECT_LT(st.at("numeric_factorizations"), solves);  // the factor is reused
      EXPECT_GT(st.at("cg_iterations"), 0);
    } else {
      EXPECT_EQ(st.at("numeric_factorizations"), solves) << name;
    }
    EXPECT_GT(st.at("assembly_seconds"), 0);
    EXPECT_GT(st.at("factorization_seconds"), 0);
    EXPECT_GT(st.at("solve_seconds"), 0);
  }
}

// Screening the contacts' set (contact_screening_tolerance, 1e-3 by default): each solve of a
// step with contacts runs CG to the loose tolerance first and is finished to cg_tolerance only
// when the set held, the impulses and friction then taken from the finished solve. On the
// slope the run stays valid, the final solves meet cg_tolerance (no not-converged steps), and
// the jelly ends as close to the unscreened run as cg_tolerance's own error (1e-5 relative:
// about 1e-5 m here; docs/implicit.md). 1e-2 screens more loosely and still stays within 1 cm.
TEST(ImplicitEuler, ContactScreeningKeepsTheRunCloseToTheUnscreenedOne) {
  Model model = build_cube(testing::small_cube(8, 1.0, Vec3(0, 0.4, 0)));  // 1,536 unknowns
  const auto run = [&](Real screening, Statistics* statistics) {
    IntegratorOptions o;
    o.implicit.contact_screening_tolerance = screening;
    Simulator sim = Simulator(model, rest_state(model), make_integrator("implicit_euler", o),
                              SimulatorOptions{1.0 / 60, 0, {}});
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
    const RunReport report = sim.run_until(0.5);
    EXPECT_TRUE(report.ok()) << report.reason;
    *statistics = report.statistics;
    return sim.state();
  };
  Statistics plain, screened, loose;
  const State a = run(0, &plain);
  const State b = run(ImplicitEulerOptions().contact_screening_tolerance, &screened);
  const State c = run(1e-2, &loose);
  for (const Statistics* s : {&screened, &loose}) {
    EXPECT_EQ(s->at("contact_not_converged"), 0);
    // Every step finishes at least one solve to cg_tolerance: more solves, each step's last
    // one at full accuracy.
    EXPECT_GT(s->at("linear_solves"), plain.at("linear_solves"));
  }
  EXPECT_LT((a.x - b.x).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT((a.x - c.x).cwiseAbs().maxCoeff(), 1e-2);
  EXPECT_TRUE(b.x.allFinite() && b.v.allFinite());
}

// Where the contacts' set never changes (a squeezed jelly falling above a coulomb slope), every
// screened solve is resumed to cg_tolerance: the run is the unscreened run bit for bit, with
// the same CG iterations (the loose and the resumed parts add up), in twice the solves.
TEST(ImplicitEuler, ScreeningWithoutSetChangesIsTheUnscreenedRun) {
  Model model = build_cube(testing::small_cube(8, 1.0, Vec3(0, 6, 0)));  // 1,536 unknowns
  State start = rest_state(model);
  for (int i = 0; i < start.x.size(); ++i) start.x[i] += 0.02 * std::sin(0.7 * i);
  const auto run = [&](Real screening, Statistics* statistics) {
    IntegratorOptions o;
    o.implicit.contact_screening_tolerance = screening;
    Simulator sim = Simulator(model, start, make_integrator("implicit_euler", o),
                              SimulatorOptions{1.0 / 60, 0, {}});
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));  // coulomb contact
    const RunReport report = sim.run_until(0.3);
    EXPECT_TRUE(report.ok()) << report.reason;
    *statistics = report.statistics;
    return sim.state();
  };
  Statistics plain, screened;
  const State a = run(0, &plain);
  const State b = run(1e-3, &screened);
  EXPECT_GT(plain.at("cg_iterations"), 0);
  EXPECT_EQ(screened.at("cg_iterations"), plain.at("cg_iterations"));
  EXPECT_EQ(screened.at("linear_solves"), 2 * plain.at("linear_solves"));
  EXPECT_EQ(screened.at("contact_extra_solves"), 0);
  EXPECT_TRUE(a.x == b.x);
  EXPECT_TRUE(a.v == b.v);
}

// Above 1000 unknowns on a lattice, auto solves matrix-free (block-Jacobi CG on the force loop's
// bands, no sparse matrix): the same trajectory as CHOLMOD's exact solves, with contact and
// friction on a slope, to the CG tolerance.
TEST(ImplicitEuler, MatrixFreeSolveAgreesWithCholmod) {
  Model model = build_cube(testing::small_cube(8, 1.0, Vec3(0, 0.4, 0)));  // 1,536 unknowns
  const auto run = [&](ImplicitLinearSolver backend, std::string* solver) {
    IntegratorOptions o;
    o.implicit.linear_solver = backend;
    o.implicit.cg_tolerance = 1e-12;
    // The same contact iterations on both paths (screening is the matrix-free CG's only).
    o.implicit.contact_screening_tolerance = 0;
    Simulator sim = Simulator(model, rest_state(model), make_integrator("implicit_euler", o),
                              SimulatorOptions{1.0 / 60, 0, {}});
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
    const RunReport report = sim.run_until(0.5);
    EXPECT_TRUE(report.ok()) << report.reason;
    EXPECT_GT(report.statistics.at("contact_extra_solves") + sim.contacts().contact_count(), 0);
    *solver = std::string(static_cast<const ImplicitEuler&>(sim.integrator()).linear_solver_name());
    return sim.state();
  };
  std::string free_name, exact_name;
  const State matrix_free = run(ImplicitLinearSolver::kAuto, &free_name);
  const State exact = run(ImplicitLinearSolver::kCholmod, &exact_name);
  EXPECT_EQ(free_name, "cg_jacobi_matrix_free");
  EXPECT_EQ(exact_name, "cholmod");
  EXPECT_LT((matrix_free.x - exact.x).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT((matrix_free.v - exact.v).cwiseAbs().maxCoeff(), 1e-5);
}

// cg_preconditioner = "multigrid" (the V-cycle of solvers/linear/detail/lattice_multigrid.hpp on
// the matrix-free path): a cube sliding down the slope with its contacts inside the solve ends
// where the block-Jacobi run ends (both to a tight CG tolerance), with far fewer CG iterations,
// and its run is the same bits on 1 and 2 threads.
TEST(ImplicitEuler, MultigridAgreesWithBlockJacobiOnAnyThreadCount) {
  Model model = build_cube(testing::small_cube(12, 1.0, Vec3(0, 0.4, 0)));  // 5,184 unknowns
  const auto run = [&](CgPreconditionerKind preconditioner, int threads, std::string* solver,
                       double* iterations) {
    IntegratorOptions o;
    o.implicit.cg_preconditioner = preconditioner;
    o.implicit.cg_tolerance = 1e-11;
    o.implicit.contact_screening_tolerance = 0;
    SimulatorOptions so{1.0 / 60, 0, {}};
    so.threads = threads;
    Simulator sim = Simulator(model, rest_state(model), make_integrator("implicit_euler", o), so);
    sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
    const RunReport report = sim.run_until(0.5);
    EXPECT_TRUE(report.ok()) << report.reason;
    EXPECT_GT(report.statistics.at("contact_extra_solves") + sim.contacts().contact_count(), 0);
    *solver = std::string(static_cast<const ImplicitEuler&>(sim.integrator()).linear_solver_name());
    *iterations = report.statistics.at("cg_iterations");
    return sim.state();
  };
  std::string jacobi_name, mg_name, mg2_name;
  double jacobi_iterations = 0, mg_iterations = 0, mg2_iterations = 0;
  const State jacobi = run(CgPreconditionerKind::kJacobi, 1, &jacobi_name, &jacobi_iterations);
  const State mg = run(CgPreconditionerKind::kMultigrid, 1, &mg_name, &mg_iterations);
  const State mg2 = run(CgPreconditionerKind::kMultigrid, 2, &mg2_name, &mg2_iterations);
  EXPECT_EQ(jacobi_name, "cg_jacobi_matrix_free");
  EXPECT_EQ(mg_name, "cg_multigrid_matrix_free");
  EXPECT_LT((mg.x - jacobi.x).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT((mg.v - jacobi.v).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT(2 * mg_iterations, jacobi_iterations);
  EXPECT_TRUE(mg2.x == mg.x);
  EXPECT_TRUE(mg2.v == mg.v);
  EXPECT_EQ(mg2_iterations, mg_iterations);
}

// Changing dt forces a fresh factor for the lagged preconditioner.
TEST(ImplicitEuler, NewDtRefreshesTheLaggedFactor) {
  const Model model = build_cube(testing::small_cube(4, 1.0));
  IntegratorOptions o;
  o.implicit.linear_solver = ImplicitLinearSolver::kCg;
  o.implicit.cg_preconditioner = CgPreconditionerKind::kCholmod;
  o.implicit.refactor_iterations = 1000;
  auto integrator = make_integrator("implicit_euler", o);
  ContactSolver contacts;
  const Dynamics dynamics(model, contacts);
  State s = rest_state(model);
  ASSERT_TRUE(integrator->step(dynamics, s, 0.01).ok);
  const double after_first = integrator->statistics().at("numeric_factorizations");
  ASSERT_TRUE(integrator->step(dynamics, s, 0.02).ok);
  EXPECT_EQ(integrator->statistics().at("numeric_factorizations"), after_first + 1);
}

// Newton on the nonlinear backward-Euler equations converges quadratically when its Jacobian is
// exact (no dampers, no definiteness fix: the symmetric K is then df/dx).
TEST(ImplicitEuler, NewtonConvergesQuadratically) {
  CubeSpec spec = testing::small_cube(3, 1.0);
  for (auto& c : spec.springs) c = SpringCoefficients{1400, 0};
  spec.gravity.setZero();
  const Model model = build_cube(spec);
  State s = rest_state(model);
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-1, 1);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) {
    s.x[i] += 0.1 * u(rng);
    s.v[i] = 2 * u(rng);
  }
  ImplicitEulerOptions o;
  o.newton_iterations = 10;
  o.newton_tolerance = 1e-13;
  o.definiteness = DefinitenessFix::kNone;
  o.linear_solver = ImplicitLinearSolver::kCholmod;
  ImplicitEuler integrator(o);
  ContactSolver contacts;
  const Dynamics dynamics(model, contacts);
  ASSERT_TRUE(integrator.step(dynamics, s, 0.02).ok);
  const std::vector<Real>& r = integrator.last_residuals();
  ASSERT_GE(r.size(), 3u);
  EXPECT_TRUE(integrator.last_converged());
  // e_{k+1} <= C e_k^2 for the residuals above rounding (normalised by the first).
  int checked = 0;
  for (size_t k = 0; k + 1 < r.size(); ++k) {
    const Real ek = r[k] / r[0], next = r[k + 1] / r[0];
    if (r[k + 1] < 1e-11 * r[0]) break;
    EXPECT_LT(next, 10 * ek * ek) << "iteration " << k;
    ++checked;
  }
  EXPECT_GE(checked, 1);
  EXPECT_LT(r.back(), 1e-13 * r[0] * 1e3);
  for (size_t k = 0; k < r.size(); ++k) std::cout << "  residual " << k << ": " << r[k] << "\n";

  // With dampers and the clamp the Jacobian is approximate: Newton still converges, linearly.
  CubeSpec damped_spec = spec;
  for (auto& c : damped_spec.springs) c = SpringCoefficients{1400, 50};
  const Model damped = build_cube(damped_spec);
  ImplicitEulerOptions od;
  od.newton_iterations = 30;
  od.newton_tolerance = 1e-10;
  ImplicitEuler approximate(od);
  const Dynamics damped_dynamics(damped, contacts);
  State sd = rest_state(damped);
  sd.x = s.x;
  sd.v.setRandom();
  ASSERT_TRUE(approximate.step(damped_dynamics, sd, 0.02).ok);
  EXPECT_TRUE(approximate.last_converged());
  EXPECT_LT(approximate.statistics().at("newton_iterations"), 31);
}

TEST(ImplicitEuler, InvalidOptionsNameTheField) {
  IntegratorOptions o;
  o.implicit.newton_iterations = 0;
  try {
    make_integrator("implicit_euler", o);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("integrator.options.newton_iterations"), std::string::npos)
        << e.what();
  }
  o = {};
  o.implicit.cg_tolerance = 0;
  EXPECT_THROW(make_integrator("implicit_euler", o), InputError);
  // A named choice outside its table, read from a scene, names the field and the names allowed;
  // an unknown ordering is an error (it was once METIS without a word).
  const auto read = [](const char* text) {
    const Json options = Json::parse(text);
    JsonFields f(options, "integrator.options");
    return ImplicitEulerOptions::read(f);
  };
  for (
      const auto& [text, expected] : std::vector<std::pair<const char*, const char*>>{
          {R"({"linear_solver": "umfpack"})",
           R"(integrator.options.linear_solver = "umfpack" is invalid: one of "auto", "cholmod", "ldlt", "cg")"},
          {R"({"ordering": "colamd"})",
           R"(integrator.options.ordering = "colamd" is invalid: one of "amd", "metis", "nesdis", "best")"},
          {R"({"cg_preconditioner": "ilu"})",
           R"(integrator.options.cg_preconditioner = "ilu" is invalid: one of "jacobi", "cholmod", "multigrid", "amg")"},
          {R"({"definiteness": "psd"})",
           R"(integrator.options.definiteness = "psd" is invalid: one of "clamp", "project", "none")"},
          {R"({"cg_tolerance": 0})",
           R"(integrator.options.cg_tolerance = 0 is invalid: a relative residual in (0, 1))"},
          {R"({"contact_screening_tolerance": 1.5})",
           R"(integrator.options.contact_screening_tolerance = 1.5 is invalid: 0 (off) or a relative residual in (0, 1))"}}) {
    try {
      read(text);
      ADD_FAILURE() << "no InputError for " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), expected);
    }
  }
  // Every option written out reads back the same.
  ImplicitEulerOptions custom;
  custom.linear_solver = ImplicitLinearSolver::kCg;
  custom.cg_preconditioner = CgPreconditionerKind::kCholmod;
  custom.ordering = CholmodOrdering::kNesdis;
  custom.contact = ImplicitContactMode::kAfterStep;
  custom.definiteness = DefinitenessFix::kProjectPsd;
  custom.newton_iterations = 3;
  const Json written = custom.to_json();
  JsonFields f(written, "integrator.options");
  EXPECT_EQ(ImplicitEulerOptions::read(f).to_json(), custom.to_json());
  f.reject_unknown();
}

// ---- Stability of the seed scenes, 5 s, at large time steps --------------------------------

struct Material {
  Real ks, kd;
};

// (For ctest's test names: gtest prints a struct without PrintTo as its bytes.)
void PrintTo(const Material& m, std::ostream* os) { *os << "ks " << m.ks << ", kd " << m.kd; }

struct SceneOutcome {
  RunReport report;
  Real deepest = 0;       // most negative signed distance to the terrain seen (m)
  Real worst_growth = 0;  // largest energy increase between frames (J)
  Real energy_scale = 0;  // initial |kinetic + elastic + gravitational| (J)
  Real initial = 0;       // initial energy (J)
  Real highest = -1e300;  // highest energy seen (J)
  Real final_energy = 0;  // energy at the end (J)
};

enum class Scene { kSlope, kElevator, kFree };

SceneOutcome run_seed_scene(Scene scene, Real dt, Material material) {
  CubeSpec spec;  // the seed cube at its seed pose
  for (auto& c : spec.springs) c = SpringCoefficients{material.ks, material.kd};
  const Model model = build_cube(spec);
  SimulatorOptions so;
  so.dt = dt;
  State s0 = rest_state(model);
  if (scene == Scene::kFree) {  // strongly deformed and moving, no terrain
    for (Eigen::Index i = 0; i < s0.x.size(); ++i) {
      s0.x[i] += 0.1 * std::sin(17.0 * static_cast<Real>(i));
      s0.v[i] = 2 * std::cos(5.0 * static_cast<Real>(i));
    }
  }
  Simulator sim(model, s0, make_integrator("implicit_euler"), so);
  if (scene == Scene::kElevator) sim.add_terrain(std::make_unique<Elevator>());
  if (scene == Scene::kSlope) sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
  const Plane no_terrain(Vec3(0, -1e6, 0), Vec3::UnitY());
  const Terrain& terrain =
      scene == Scene::kFree ? static_cast<const Terrain&>(no_terrain) : *sim.terrains()[0];
  SceneOutcome out;
  Real previous = total_energy(model, sim.state());
  out.energy_scale = std::abs(previous);
  out.initial = previous;
  testing::Probe probe([&](const Simulator& s) {
    for (int i = 0; i < model.num_particles(); ++i) {
      const Vec3 p = particle(s.state().x, i);
      if (terrain.can_contact(p, s.state().t))
        out.deepest = std::min(out.deepest, terrain.signed_distance(p, s.state().t));
    }
    const Real e = total_energy(model, s.state());
    out.worst_growth = std::max(out.worst_growth, e - previous);
    out.highest = std::max(out.highest, e);
    previous = e;
  });
  sim.add_observer(probe);
  out.report = sim.run_until(5.0);
  out.final_energy = total_energy(model, sim.state());
  return out;
}

class SeedScenes : public ::testing::TestWithParam<std::tuple<Real, Material>> {};

std::string material_name(const Material& m) {
  return "ks" + std::to_string(static_cast<int>(m.ks)) + "_kd" +
         std::to_string(static_cast<int>(m.kd));
}

INSTANTIATE_TEST_SUITE_P(
    Implicit, SeedScenes,
    ::testing::Combine(::testing::Values(1.0 / 60, 1.0 / 30),
                       ::testing::Values(Material{1400, 50}, Material{2400, 120},
                                         Material{100000, 50})),
    [](const ::testing::TestParamInfo<std::tuple<Real, Material>>& p) {
      return "dt1_" + std::to_string(static_cast<int>(std::round(1 / std::get<0>(p.param)))) + "_" +
             material_name(std::get<1>(p.param));
    });

// Without terrain nothing does work on the jelly but gravity, whose work is in the energy:
// implicit Euler only dissipates, so the energy never grows, at any of these time steps.
TEST_P(SeedScenes, FreeJellyNeverGainsEnergy) {
  const auto [dt, material] = GetParam();
  const SceneOutcome out = run_seed_scene(Scene::kFree, dt, material);
  ASSERT_TRUE(out.report.ok()) << out.report.brief();
  EXPECT_LE(out.worst_growth, 1e-9 * out.energy_scale);
}

// The slope: no divergence, never more than 5 cm into the slope (with contact inside the solve
// it is never inside at all), and, since nothing does work on the jelly on the fixed slope but
// gravity, whose work is in the energy, the energy never grows from one frame to the next,
// through the fall, the impact and the rest, at these large steps. (With contact after the
// step, "after_step", it grew up to 1.65x at dt = 1/30 and 50x at ks = 1e5: the projection
// crushed the springs above the bottom layer.)
TEST_P(SeedScenes, SlopeIsStableAndNeverGainsEnergy) {
  const auto [dt, material] = GetParam();
  const SceneOutcome out = run_seed_scene(Scene::kSlope, dt, material);
  ASSERT_TRUE(out.report.ok()) << out.report.brief();
  EXPECT_GT(out.deepest, -1e-9);
  EXPECT_LE(out.worst_growth, 1e-9 * out.energy_scale);
  EXPECT_LT(out.final_energy, out.initial);
}

// The elevator does work on the jelly, so only stability and contact are checked: no
// divergence and never more than 5 cm into the moving platform.
TEST_P(SeedScenes, ElevatorIsStable) {
  const auto [dt, material] = GetParam();
  const SceneOutcome out = run_seed_scene(Scene::kElevator, dt, material);
  ASSERT_TRUE(out.report.ok()) << out.report.brief();
  EXPECT_GT(out.deepest, -0.05);
}

// A stiff anchor spring (the viewer's mouse drag) at dt = 1/60: its Jacobian is part of the
// solve, so the step stays stable (an explicit treatment, h sqrt(k / m) = 5.3, would not) and
// the dragged corner follows the target, on the floor with coulomb contact inside the solve too.
TEST(ImplicitEuler, StiffAnchorAtOneSixtieth) {
  for (const bool floor : {false, true}) {
    SCOPED_TRACE(floor ? "on a coulomb floor" : "in the air");
    const Model model = build_cube(testing::small_cube(4, 1, Vec3(0, 0.001, 0)));
    SimulatorOptions options;
    options.dt = 1.0 / 60;
    Simulator sim(model, rest_state(model), make_integrator("implicit_euler"), options);
    if (floor) {
      ContactParams contact;
      contact.model = ContactModel::kCoulomb;
      sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY(), contact));
    }
    const int corner = cube_index(4, 3, 3, 3);
    const Vec3 target = Vec3(particle(sim.state().x, corner)) + Vec3(0.3, 1.0, 0.2);
    sim.set_anchors({AnchorSpring{corner, target, 1e5, 200}});
    const RunReport report = sim.run_until(3.0);
    ASSERT_TRUE(report.ok()) << report.reason;
    ASSERT_TRUE(sim.state().x.allFinite());
    // The anchor carries the cube's weight (64 kg: about 6 mm of stretch); the cube swings
    // about it as a pendulum.
    EXPECT_LT((Vec3(particle(sim.state().x, corner)) - target).norm(), 0.02);
    EXPECT_LT(sim.state().v.cwiseAbs().maxCoeff(), 1.0);
  }
}

// The anchor's Jacobian enters the solve: a particle on an anchor of k = 1e6 N/m at h = 1/60
// (h^2 k / m = 278) decays to the target; taken explicitly it would grow 278-fold per step.
TEST(ImplicitEuler, AnchorJacobianInTheSolve) {
  Model model;
  model.mass = VecX::Constant(1, 1.0);
  model.rest_position = VecX::Zero(3);
  model.gravity.setZero();
  State s;
  s.x = Vec3(0.1, 0, 0);
  s.v = VecX::Zero(3);
  Simulator sim = testing::make_sim(model, s, "implicit_euler", 1.0 / 60);
  sim.set_anchors({AnchorSpring{0, Vec3::Zero(), 1e6, 0}});
  for (int i = 0; i < 60; ++i) ASSERT_TRUE(sim.step().ok);
  EXPECT_LT(std::abs(sim.state().x[0]), 0.1);
  EXPECT_LT(std::abs(sim.state().x[0]), 1e-3);
}

}  // namespace
}  // namespace jelly
