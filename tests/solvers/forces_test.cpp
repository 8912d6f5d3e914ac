// Forces of the user's inside every integrator, and the live model: edits between steps.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

// -m g on every particle: with it a free body floats.
class AntiGravity final : public Force {
 public:
  explicit AntiGravity(const Model& model) : mass_(model.mass), gravity_(model.gravity) {}
  std::string name() const override { return "anti_gravity"; }
  void add_forces(Real, const VecX&, const VecX&, VecX& f) const override {
    for (int i = 0; i < mass_.size(); ++i) f.segment<3>(3 * i) -= mass_[i] * gravity_;
  }

 private:
  VecX mass_;
  Vec3 gravity_;
};

// Every particle pulled to its rest position plus `shift` by a spring k (damping c).
class SpringsToAnchors final : public Force {
 public:
  SpringsToAnchors(const Model& model, Vec3 shift, Real k, Real c, bool jacobian)
      : anchors_(model.rest_position), k_(k), c_(c), jacobian_(jacobian) {
    for (int i = 0; i < model.num_particles(); ++i) anchors_.segment<3>(3 * i) += shift;
  }
  std::string name() const override { return "springs_to_anchors"; }
  void add_forces(Real, const VecX& x, const VecX& v, VecX& f) const override {
    f -= k_ * (x - anchors_) + c_ * v;
  }
  bool has_jacobian() const override { return jacobian_; }
  void add_jacobian(Real, const VecX&, const VecX&, ForceJacobian& j) const override {
    for (int i = 0; i < anchors_.size() / 3; ++i)
      j.add(i, i, -k_ * Mat3::Identity(), -c_ * Mat3::Identity());
  }
  Real energy(const VecX& x) const { return 0.5 * k_ * (x - anchors_).squaredNorm(); }

 private:
  VecX anchors_;
  Real k_, c_;
  bool jacobian_;
};

// A cube of n^3 particles, deformed (stretched along x) so that its springs work.
Simulator deformed_cube(int n, std::unique_ptr<Integrator> integrator, Real dt = 1e-3) {
  Model model = build_cube(testing::small_cube(n, 1, Vec3(0, 2, 0)));
  State state = rest_state(model);
  for (int i = 0; i < model.num_particles(); ++i) state.x[3 * i] *= 1.1;
  SimulatorOptions options;
  options.dt = dt;
  return Simulator(std::move(model), std::move(state), std::move(integrator), options);
}

std::unique_ptr<Integrator> implicit(ImplicitLinearSolver solver) {
  IntegratorOptions o;
  o.implicit.linear_solver = solver;
  return make_integrator("implicit_euler", o);
}

TEST(AddedForces, CancellingGravityKeepsAFreeCubesCentreStillUnderEveryKindOfMethod) {
  struct Case {
    std::string label;
    std::unique_ptr<Integrator> (*make)();
    int n;
    Real dt;
  };
  const std::vector<Case> cases = {
      {"rk4", [] { return make_integrator("rk4"); }, 4, 1e-3},
      {"implicit_euler (cholmod)", [] { return implicit(ImplicitLinearSolver::kCholmod); }, 4,
       1.0 / 60},
      // More than 1,000 unknowns: auto takes block-Jacobi CG on the bands (matrix-free).
      {"implicit_euler (matrix-free)", [] { return implicit(ImplicitLinearSolver::kAuto); }, 8,
       1.0 / 60},
      {"xpbd", [] { return make_integrator("xpbd"); }, 4, 1.0 / 60},
      {"projective_dynamics", [] { return make_integrator("projective_dynamics"); }, 4, 1.0 / 60},
  };
  for (const Case& c : cases) {
    Simulator sim = deformed_cube(c.n, c.make(), c.dt);
    const Vec3 start = center_of_mass(sim.model(), sim.state());
    sim.add_force(std::make_shared<AntiGravity>(sim.model()));
    const RunReport report = sim.run_until(1.0);
    ASSERT_TRUE(report.ok()) << c.label << ": " << report.brief();
    EXPECT_LT((center_of_mass(sim.model(), sim.state()) - start).norm(), 1e-9) << c.label;
    // ... while the springs did work (the cube is not frozen).
    EXPECT_GT(kinetic_energy(sim.model(), sim.state()) + elastic_energy(sim.model(), sim.state()),
              0)
        << c.label;
    if (c.label == "implicit_euler (matrix-free)") {
      EXPECT_EQ(static_cast<const ImplicitEuler&>(sim.integrator()).linear_solver_name(),
                "cg_jacobi_matrix_free");
    }
  }
}

// Wind drag (a scene force) on a free cube under implicit_euler's matrix-free CG: the centre
// follows backward Euler's own recursion for dv/dt = c (w - v) / m. The momentum correction of
// an iterative solve (which assumes 1^T A = 1^T M) must not act when the drag adds to A's
// diagonal: it did, and the centre drifted too far.
TEST(AddedForces, WindUnderMatrixFreeImplicitEulerFollowsBackwardEuler) {
  Simulator sim = deformed_cube(8, implicit(ImplicitLinearSolver::kAuto), 0.01);
  Model model = sim.model();
  ExternalForce wind;
  wind.kind = ExternalForceKind::kWind;
  for (int i = 0; i < model.num_particles(); ++i) wind.particles.push_back(i);
  wind.vector = Vec3(0, 0, 3);
  wind.drag = 0.5;
  model.external_forces.push_back(wind);
  model.gravity.setZero();
  IntegratorOptions tight;
  tight.implicit.cg_tolerance = 1e-12;  // so that CG's own error is far below the tolerance
  Simulator windy(model, sim.state(), make_integrator("implicit_euler", tight), sim.options());
  const Real z0 = center_of_mass(windy.model(), windy.state()).z();
  windy.run_until(0.5);
  EXPECT_EQ(static_cast<const ImplicitEuler&>(windy.integrator()).linear_solver_name(),
            "cg_jacobi_matrix_free");
  Real v = 0, z = 0;
  for (int k = 0; k < 50; ++k) {
    v = (v + 0.01 * 0.5 * 3) / (1 + 0.01 * 0.5);
    z += 0.01 * v;
  }
  EXPECT_NEAR(center_of_mass(windy.model(), windy.state()).z() - z0, z, 1e-9);
}

TEST(AddedForces, WithoutTheForceTheCubeFalls) {  // the test above can fail
  Simulator sim = deformed_cube(4, make_integrator("rk4"));
  const Vec3 start = center_of_mass(sim.model(), sim.state());
  sim.run_until(0.5);
  EXPECT_NEAR(center_of_mass(sim.model(), sim.state()).y() - start.y(), -0.5 * 9.8 * 0.25, 1e-6);
}

TEST(AddedForces, AStiffForceWithItsJacobianIsStableAndLosesEnergyAtLargeSteps) {
  for (const auto solver : {ImplicitLinearSolver::kCholmod, ImplicitLinearSolver::kCg}) {
    Simulator sim = deformed_cube(4, implicit(solver), 1.0 / 30);
    sim.set_gravity(Vec3::Zero());
    const auto force =
        std::make_shared<SpringsToAnchors>(sim.model(), Vec3(0.05, 0, 0), 1e6, 0, true);
    sim.add_force(force);
    const auto energy = [&] {
      return kinetic_energy(sim.model(), sim.state()) + elastic_energy(sim.model(), sim.state()) +
             force->energy(sim.state().x);
    };
    const Real e0 = energy();
    Real last = e0;
    for (int k = 0; k < 30; ++k) {
      ASSERT_TRUE(sim.step().ok);
      const Real e = energy();
      ASSERT_TRUE(std::isfinite(e));
      EXPECT_LE(e, last + 1e-12 * e0) << "step " << k;
      last = e;
    }
    EXPECT_LT(last, 1e-6 * e0);  // backward Euler damps the stiff oscillation out
    EXPECT_TRUE(sim.run_until(sim.state().t + 0.1).notes.empty());
  }
}

// A spring k between two particles far apart in the lattice (its blocks lie off the springs'
// bands), with its Jacobian.
class Tether final : public Force {
 public:
  Tether(int a, int b, Real k) : a_(a), b_(b), k_(k) {}
  std::string name() const override { return "tether"; }
  void add_forces(Real, const VecX& x, const VecX&, VecX& f) const override {
    const Vec3 d = x.segment<3>(3 * a_) - x.segment<3>(3 * b_);
    f.segment<3>(3 * a_) -= k_ * d;
    f.segment<3>(3 * b_) += k_ * d;
  }
  bool has_jacobian() const override { return true; }
  void add_jacobian(Real, const VecX&, const VecX&, ForceJacobian& j) const override {
    const Mat3 k = k_ * Mat3::Identity();
    j.add(a_, a_, -k, Mat3::Zero());
    j.add(a_, b_, k, Mat3::Zero());
    j.add(b_, a_, k, Mat3::Zero());
    j.add(b_, b_, -k, Mat3::Zero());
  }

 private:
  int a_, b_;
  Real k_;
};

// implicit_euler's matrix-free CG takes an added force's Jacobian into its products and its
// block-Jacobi diagonal (it went to the assembled matrix before): a stiff tether between two
// opposite corners of the cube, at 1/30 s, ends where CHOLMOD's exact solves end, and the
// same bits on 1 and 2 threads.
TEST(AddedForces, MatrixFreeCgTakesAForcesJacobianIntoItsProducts) {
  const auto run = [](ImplicitLinearSolver solver, int threads, std::string* name) {
    IntegratorOptions o;
    o.implicit.linear_solver = solver;
    o.implicit.cg_tolerance = 1e-12;
    Simulator sim = deformed_cube(8, make_integrator("implicit_euler", o), 1.0 / 30);
    sim.set_threads(threads);
    sim.set_gravity(Vec3::Zero());
    sim.add_force(std::make_shared<Tether>(0, sim.model().num_particles() - 1, 1e5));
    const RunReport report = sim.run_until(0.5);
    EXPECT_TRUE(report.ok()) << report.brief();
    EXPECT_TRUE(report.notes.empty());  // the force is not treated explicitly
    *name = std::string(static_cast<const ImplicitEuler&>(sim.integrator()).linear_solver_name());
    return sim.state();
  };
  std::string free_name, free2_name, exact_name;
  const State free = run(ImplicitLinearSolver::kCg, 1, &free_name);
  const State free2 = run(ImplicitLinearSolver::kCg, 2, &free2_name);
  const State exact = run(ImplicitLinearSolver::kCholmod, 1, &exact_name);
  EXPECT_EQ(free_name, "cg_jacobi_matrix_free");
  EXPECT_EQ(exact_name, "cholmod");
  EXPECT_LT((free.x - exact.x).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT((free.v - exact.v).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_TRUE(free.x == free2.x && free.v == free2.v);
  // The corners came closer (the tether worked): 1.1 x 1 x 1 m apart at the start.
  const Vec3 gap = free.x.segment<3>(0) - free.x.tail<3>();
  EXPECT_LT(gap.norm(), 0.9 * std::sqrt(1.1 * 1.1 + 2));
}

// arkode_dirk's iterative Newton solves ("cg", the default) take a force's Jacobian into their
// operator: a stiff force then costs fewer Newton iterations than under "schur", whose matrix
// leaves it out (and whose run says so once); both end at the same state.
TEST(AddedForces, ArkodeDirkTakesAForcesJacobianIntoItsNewtonSolves) {
  const auto run = [](ArkodeLinearSolver solver, RunReport* report) {
    IntegratorOptions o;
    o.arkode.linear_solver = solver;
    Simulator sim = deformed_cube(3, make_integrator("arkode_dirk", o), 1.0 / 30);
    sim.set_gravity(Vec3::Zero());
    sim.add_force(std::make_shared<SpringsToAnchors>(sim.model(), Vec3(0.05, 0, 0), 1e4, 0, true));
    *report = sim.run_until(0.5);
    EXPECT_TRUE(report->ok()) << report->brief();
    return sim.state();
  };
  RunReport cg, schur;
  const State with = run(ArkodeLinearSolver::kCg, &cg);
  const State without = run(ArkodeLinearSolver::kSchur, &schur);
  EXPECT_TRUE(cg.notes.empty());
  ASSERT_EQ(schur.notes.size(), 1u);
  EXPECT_NE(schur.notes[0].find("Newton matrix leaves added forces out"), std::string::npos);
  EXPECT_LT(cg.statistics.at("newton_iterations"), schur.statistics.at("newton_iterations"));
  EXPECT_LT((with.x - without.x).cwiseAbs().maxCoeff(), 1e-3);
}

// projective_dynamics evaluates every force at each iterate and puts an added force's Jacobian
// into its factor (as it does the anchor springs'): a stiff force stays stable and loses its
// energy with it; without it the iterations diverge at the first step, and the run says why.
TEST(AddedForces, ProjectiveDynamicsTakesAForcesJacobianIntoItsFactor) {
  const auto run = [](bool jacobian, RunReport* report) {
    IntegratorOptions o;
    o.pd.tolerance = 1e-6;
    o.pd.iterations = 200;
    Simulator sim = deformed_cube(3, make_integrator("projective_dynamics", o), 1.0 / 30);
    sim.set_gravity(Vec3::Zero());
    const auto force =
        std::make_shared<SpringsToAnchors>(sim.model(), Vec3(0.05, 0, 0), 1e5, 0, jacobian);
    sim.add_force(force);
    const Real e0 = kinetic_energy(sim.model(), sim.state()) +
                    elastic_energy(sim.model(), sim.state()) + force->energy(sim.state().x);
    *report = sim.run_until(0.5);
    const Real e = kinetic_energy(sim.model(), sim.state()) +
                   elastic_energy(sim.model(), sim.state()) + force->energy(sim.state().x);
    return e / e0;
  };
  RunReport with, without;
  const Real kept = run(true, &with);
  run(false, &without);
  EXPECT_TRUE(with.ok()) << with.brief();
  EXPECT_TRUE(with.notes.empty());
  EXPECT_LT(kept, 1e-3);  // backward Euler damps the stiff oscillation out
  ASSERT_GE(without.notes.size(), 1u);
  EXPECT_EQ(without.notes[0],
            "force 'springs_to_anchors' gives no Jacobian: projective_dynamics evaluates it at "
            "every iterate, but its factor leaves it out (a stiff force can keep the iterations "
            "from converging)");
  EXPECT_TRUE(!without.ok() || without.statistics.at("not_converged") > 0) << without.brief();
}

TEST(AddedForces, WithoutItsJacobianTheForceIsSaidToBeExplicitOnce) {
  Simulator sim = deformed_cube(3, implicit(ImplicitLinearSolver::kCholmod), 1.0 / 30);
  sim.add_force(std::make_shared<SpringsToAnchors>(sim.model(), Vec3::Zero(), 10, 0, false));
  const RunReport first = sim.run_until(0.1);
  ASSERT_EQ(first.notes.size(), 1u);
  EXPECT_EQ(first.notes[0],
            "force 'springs_to_anchors' gives no Jacobian: implicit_euler treats it explicitly "
            "within each step");
  EXPECT_TRUE(sim.run_until(0.2).notes.empty());  // once
}

TEST(AddedForces, RemovingAForceByItsHandle) {
  Simulator sim = deformed_cube(3, make_integrator("rk4"));
  const ForceHandle h = sim.add_force(std::make_shared<AntiGravity>(sim.model()));
  EXPECT_EQ(sim.forces().size(), 1u);
  EXPECT_TRUE(sim.remove_force(h));
  EXPECT_FALSE(sim.remove_force(h));
  EXPECT_TRUE(sim.forces().empty());
  EXPECT_THROW(sim.add_force(nullptr), InputError);
}

TEST(AddedForces, AFailingForceLeavesTheSimulatorAtTheLastCompletedStep) {
  class Failing final : public Force {
   public:
    std::string name() const override { return "failing"; }
    void add_forces(Real t, const VecX&, const VecX&, VecX&) const override {
      if (t > 0.0505) throw std::runtime_error("the controller lost its input");
    }
  };
  for (const char* name : {"rk4", "implicit_euler"}) {
    Simulator sim = deformed_cube(3, make_integrator(name));
    sim.add_force(std::make_shared<Failing>());
    EXPECT_THROW(sim.run_until(1.0), std::runtime_error);
    Simulator reference = deformed_cube(3, make_integrator(name));
    reference.run_until(sim.state().t);
    EXPECT_EQ(sim.total_steps(), reference.total_steps()) << name;
    EXPECT_EQ(sim.state().x, reference.state().x) << name;
    EXPECT_EQ(sim.state().v, reference.state().v) << name;
  }
}

// A run that edits ks mid-way equals, bit for bit, a run restored at the edit into a simulator
// whose model had that ks from the start.
TEST(LiveModel, AKsChangeMidRunEqualsAFreshRunWithThatKs) {
  for (const char* name : {"rk4", "implicit_euler", "projective_dynamics", "xpbd"}) {
    Simulator edited = deformed_cube(3, make_integrator(name), 1.0 / 120);
    edited.add_terrain(std::make_unique<Plane>(Vec3(0, 1.6, 0), Vec3(0, 1, 0)));
    edited.run_until(0.25);
    const SimulatorSnapshot at_edit = edited.snapshot();
    edited.set_spring_coefficients(0, SpringType::kShear, {3000, 20});
    edited.set_gravity(Vec3(1, -5, 0));
    edited.run_until(0.5);

    Model model = edited.model();  // the edited model, built afresh
    Simulator fresh(std::move(model), at_edit.state, make_integrator(name), edited.options());
    fresh.add_terrain(std::make_unique<Plane>(Vec3(0, 1.6, 0), Vec3(0, 1, 0)));
    fresh.restore(at_edit);
    fresh.run_until(0.5);
    EXPECT_EQ(edited.state().x, fresh.state().x) << name;
    EXPECT_EQ(edited.state().v, fresh.state().v) << name;

    // ... and differs from a run without the edit.
    Simulator unedited = deformed_cube(3, make_integrator(name), 1.0 / 120);
    unedited.add_terrain(std::make_unique<Plane>(Vec3(0, 1.6, 0), Vec3(0, 1, 0)));
    unedited.run_until(0.5);
    EXPECT_NE(edited.state().x, unedited.state().x) << name;
  }
}

// A terrain moved mid-run (replace_terrain) equals, bit for bit, a run restored at the move into
// a simulator that had the terrain there from the start; the other terrains keep their indices.
TEST(LiveModel, AMovedTerrainMidRunEqualsAFreshRunWithItThere) {
  for (const char* name : {"rk4", "implicit_euler", "projective_dynamics", "xpbd"}) {
    Simulator edited = deformed_cube(3, make_integrator(name), 1.0 / 120);
    edited.add_terrain(std::make_unique<Plane>(Vec3(0, 1.6, 0), Vec3(0, 1, 0)));
    edited.add_terrain(std::make_unique<Plane>(Vec3(-5, 0, 0), Vec3(1, 0, 0)));
    edited.run_until(0.25);
    const SimulatorSnapshot at_edit = edited.snapshot();
    edited.replace_terrain(0, std::make_unique<Plane>(Vec3(0, 1.7, 0), Vec3(0, 1, 0)));
    ASSERT_EQ(edited.terrains().size(), 2u);
    EXPECT_EQ(edited.terrains()[0]->position(0).y(), 1.7) << name;
    EXPECT_EQ(edited.terrains()[1]->position(0).x(), -5) << name;
    edited.run_until(0.5);

    Simulator fresh(edited.model(), at_edit.state, make_integrator(name), edited.options());
    fresh.add_terrain(std::make_unique<Plane>(Vec3(0, 1.7, 0), Vec3(0, 1, 0)));
    fresh.add_terrain(std::make_unique<Plane>(Vec3(-5, 0, 0), Vec3(1, 0, 0)));
    fresh.restore(at_edit);
    fresh.run_until(0.5);
    EXPECT_EQ(edited.state().x, fresh.state().x) << name;
    EXPECT_EQ(edited.state().v, fresh.state().v) << name;

    // ... and differs from a run without the move (the floor rose into the falling cube).
    Simulator unmoved = deformed_cube(3, make_integrator(name), 1.0 / 120);
    unmoved.add_terrain(std::make_unique<Plane>(Vec3(0, 1.6, 0), Vec3(0, 1, 0)));
    unmoved.add_terrain(std::make_unique<Plane>(Vec3(-5, 0, 0), Vec3(1, 0, 0)));
    unmoved.run_until(0.5);
    EXPECT_NE(edited.state().x, unmoved.state().x) << name;
  }
}

// A terrain removed mid-run shifts the indices of those after it: implicit_euler's contacts
// carried from the last step (stick or slide, friction viscosity) follow their terrain, so the
// run equals, bit for bit, one that never had the removed terrain (untouched by the cube).
TEST(LiveModel, ARemovedTerrainMidRunEqualsARunThatNeverHadIt) {
  const Real a = 0.6;  // a slope steeper than the friction holds: the cube slides
  ContactParams contact;
  contact.restitution = 0;
  const auto slope = [&] {
    return std::make_unique<Plane>(Vec3(0, 1.6, 0), Vec3(std::sin(a), std::cos(a), 0), contact);
  };
  Simulator edited = deformed_cube(3, make_integrator("implicit_euler"), 1.0 / 120);
  edited.add_terrain(std::make_unique<Plane>(Vec3(-5, 0, 0), Vec3(1, 0, 0)));
  edited.add_terrain(slope());
  Simulator never = deformed_cube(3, make_integrator("implicit_euler"), 1.0 / 120);
  never.add_terrain(slope());
  edited.run_until(0.6);
  never.run_until(0.6);
  ASSERT_EQ(edited.state().x, never.state().x);
  Real lowest = 1;  // the cube rests on the slope at the removal
  for (int i = 0; i < never.model().num_particles(); ++i)
    lowest =
        std::min(lowest, never.terrains()[0]->signed_distance(particle(never.state().x, i), 0.6));
  ASSERT_LT(lowest, 1e-6);
  edited.remove_terrain(0);
  edited.run_until(0.9);
  never.run_until(0.9);
  EXPECT_EQ(edited.state().x, never.state().x);
  EXPECT_EQ(edited.state().v, never.state().v);
}

TEST(LiveModel, InvalidEditsThrowNamingTheFieldAndChangeNothing) {
  Simulator sim = deformed_cube(3, make_integrator("rk4"));
  const Model before = sim.model();
  const auto expect_message = [](auto edit, const std::string& message) {
    try {
      edit();
      FAIL() << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  expect_message(
      [&] {
        sim.set_spring_coefficients(0, SpringType::kBending, {-1, 2});
      },
      "bodies[0].springs.bending.ks = -1 is invalid");
  expect_message(
      [&] {
        sim.set_spring_coefficients(2, SpringType::kBending, {1, 2});
      },
      "body = 2 is invalid");
  expect_message([&] { sim.set_particle_mass(0, 0); }, "bodies[0].particle_mass = 0 is invalid");
  expect_message([&] { sim.set_gravity(Vec3(0, NAN, 0)); }, "gravity");
  expect_message([&] { sim.set_dt(-1); }, "integrator.dt = -1 is invalid");
  expect_message([&] { sim.set_pin_target(0, Vec3::Zero()); }, "pin particle = 0 is invalid");
  expect_message([&] { sim.remove_terrain(0); }, "terrain index = 0 is invalid");
  expect_message(
      [&] { sim.replace_terrain(0, std::make_unique<Plane>(Vec3::Zero(), Vec3(0, 1, 0))); },
      "terrain index = 0 is invalid");
  sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3(0, 1, 0)));
  expect_message([&] { sim.replace_terrain(0, nullptr); }, "terrain = null is invalid");
  EXPECT_EQ(sim.terrains().size(), 1u);
  EXPECT_EQ(sim.model().springs.ks, before.springs.ks);
  EXPECT_EQ(sim.model().mass, before.mass);
  EXPECT_EQ(sim.model().gravity, before.gravity);
  EXPECT_EQ(sim.options().dt, 1e-3);
}

TEST(LiveModel, MassEditsMoveTheSameForcesSlower) {
  Simulator sim = deformed_cube(2, make_integrator("rk4"));
  sim.set_gravity(Vec3::Zero());
  sim.set_particle_mass(0, 4);
  sim.add_force(std::make_shared<AntiGravity>(deformed_cube(2, make_integrator("rk4")).model()));
  sim.run_until(0.5);  // -m g with m = 1, g = -9.8: 9.8 N up on 4 kg
  EXPECT_NEAR(linear_momentum(sim.model(), sim.state()).y(), 8 * 9.8 * 0.5, 1e-9);
}

// Counts frames.
class Frames final : public Observer {
 public:
  void on_frame(const Simulator&) override { ++count; }
  int count = 0;
};

TEST(LiveModel, SwitchingTheIntegratorKeepsTerrainsForcesPinsAndOutput) {
  Simulator sim = deformed_cube(3, make_integrator("rk4"));
  sim.set_output_interval(0.1);
  sim.add_terrain(std::make_unique<Plane>(Vec3(0, 1.5, 0), Vec3(0, 1, 0)));
  sim.add_force(std::make_shared<SpringsToAnchors>(sim.model(), Vec3::Zero(), 1, 0, true));
  sim.set_pin(26, particle(sim.model().rest_position, 26), Path());
  Frames frames;
  sim.add_observer(frames);
  sim.run_until(0.2);
  sim.set_integrator(make_integrator("implicit_euler"));
  sim.set_dt(1.0 / 60);
  const RunReport report = sim.run_until(3.0);
  ASSERT_TRUE(report.ok()) << report.brief();
  EXPECT_EQ(sim.integrator().name(), "implicit_euler");
  EXPECT_EQ(sim.terrains().size(), 1u);
  EXPECT_EQ(sim.forces().size(), 1u);
  EXPECT_EQ(sim.model().pins.size(), 1);
  EXPECT_EQ(particle(sim.state().x, 26), particle(sim.model().rest_position, 26));
  EXPECT_EQ(frames.count, 31);  // t = 0, 0.1, ..., 3.0
  // The terrain still holds the cube: nothing fell through the floor.
  EXPECT_GT(testing::min_distance(sim, *sim.terrains()[0]), -0.05);
  EXPECT_THROW(sim.set_integrator(nullptr), InputError);
}

TEST(LiveModel, APinOnACircleStaysOnItWithContinuousVelocity) {
  Simulator sim = deformed_cube(3, make_integrator("rk4"));
  const Vec3 anchor = particle(sim.model().rest_position, 0);
  const Vec3 center = anchor + Vec3(0.3, 0, 0.4);  // radius 0.5 about the y axis
  sim.set_pin(0, anchor, Path::circle(Vec3(0.3, 0, 0.4), Vec3(0, 1, 0), 0.7));
  ASSERT_TRUE(sim.step().ok);  // from rest onto the circle: the one jump
  Vec3 last_v = particle(sim.state().v, 0);
  Real largest_jump = 0;
  for (int k = 0; k < 2000; ++k) {
    ASSERT_TRUE(sim.step().ok);
    const Vec3 x = particle(sim.state().x, 0);
    EXPECT_NEAR((x - center).norm(), 0.5, 1e-12);
    EXPECT_NEAR(x.y(), center.y(), 1e-12);
    const Vec3 v = particle(sim.state().v, 0);
    largest_jump = std::max(largest_jump, (v - last_v).norm());
    last_v = v;
  }
  // Speed 2 pi r / T = 4.49 m/s, turning by 2 pi dt / T per step.
  EXPECT_LT(largest_jump, 2 * M_PI * 0.5 / 0.7 * (2 * M_PI * 1e-3 / 0.7) * 1.01);
}

TEST(LiveModel, CubicKeyframesHaveContinuousVelocity) {
  const Path p = Path::cubic_keyframes({0.5, 1, 2}, {Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 0, 2)});
  for (Real t : {0.0, 0.5, 1.0, 2.0}) {
    const Real e = 1e-9;
    EXPECT_LT((p.sample(t - e).velocity - p.sample(t + e).velocity).norm(), 1e-6) << t;
    EXPECT_LT((p.sample(t - e).offset - p.sample(t + e).offset).norm(), 1e-8) << t;
  }
  EXPECT_EQ(p.sample(1).offset, Vec3(1, 1, 0));
  EXPECT_EQ(p.sample(5).offset, Vec3(0, 0, 2));
  EXPECT_EQ(p.sample(5).velocity, Vec3::Zero());
  // The same keyframes joined linearly jump in velocity at t = 1.
  const Path linear = Path::keyframes({0.5, 1, 2}, {Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 0, 2)});
  EXPECT_GT((linear.sample(1 - 1e-9).velocity - linear.sample(1 + 1e-9).velocity).norm(), 1);
  // Finite differences of the offset give the velocity and acceleration.
  for (Real t : {0.2, 0.7, 1.3, 1.9}) {
    const Real h = 1e-5;
    const Vec3 v = (p.sample(t + h).offset - p.sample(t - h).offset) / (2 * h);
    const Vec3 a = (p.sample(t + h).velocity - p.sample(t - h).velocity) / (2 * h);
    EXPECT_LT((v - p.sample(t).velocity).norm(), 1e-6) << t;
    EXPECT_LT((a - p.sample(t).acceleration).norm(), 1e-5) << t;
  }
}

TEST(LiveModel, APinDrivenFromCodeFollowsItsTarget) {
  Simulator sim = deformed_cube(3, make_integrator("implicit_euler"), 0.01);
  sim.set_pin(5, particle(sim.model().rest_position, 5), Path());
  sim.run_until(0.1);
  const Real now = sim.state().t;
  sim.set_pin_target(5, Vec3(1, 3, 0), Vec3(0, 0, 2));
  const std::size_t paths = sim.model().pins.paths.size();
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(sim.step().ok);
    const Real t = sim.state().t;
    EXPECT_LT((particle(sim.state().x, 5) - Vec3(1, 3, 2 * (t - now))).norm(), 1e-12);
    EXPECT_EQ(particle(sim.state().v, 5), Vec3(0, 0, 2));
    sim.set_pin_target(5, particle(sim.state().x, 5), Vec3(0, 0, 2));  // a controller
  }
  EXPECT_EQ(sim.model().pins.paths.size(), paths);  // driving a pin grows nothing
  EXPECT_TRUE(sim.remove_pin(5));
  EXPECT_FALSE(sim.remove_pin(5));
}

}  // namespace
}  // namespace jelly
