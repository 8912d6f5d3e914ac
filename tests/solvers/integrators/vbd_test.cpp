// Vertex block descent (solvers/integrators/detail/vbd.hpp): its colouring, its conservation laws,
// its rest state against backward Euler's static solution, the impact that crushes xpbd's jelly,
// and its independence of the thread count (docs/realtime.md).
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <random>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/detail/vbd.hpp>
#include <jelly/solvers/integrators/detail/vertex_colouring.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

Simulator vbd_sim(const Model& model, const State& s, Real dt, const VbdOptions& vbd = {},
                  int threads = 1) {
  IntegratorOptions o;
  o.vbd = vbd;
  SimulatorOptions so;
  so.dt = dt;
  so.threads = threads;
  return Simulator(model, s, make_integrator("vbd", o), so);
}

// Every particle has one colour; two particles of one colour share a spring only when they are
// in one class; the classes are the lattice's symmetry classes: mirror images across each
// mid-plane, and the axes' permutations, share a class.
TEST(Vbd, ColouringSeparatesEverySpringOutsideAClass) {
  for (const int n : {4, 5}) {
    SCOPED_TRACE(n);
    const Model m = build_cube(testing::small_cube(n));
    const VertexColouring g = colour_vertices(m.num_particles(), m.springs);
    ASSERT_GT(g.colours(), 1);
    std::vector<int> colour(m.num_particles(), -1);
    for (int c = 0; c < g.colours(); ++c)
      for (int p = g.colour_start[c]; p < g.colour_start[c + 1]; ++p) {
        ASSERT_EQ(colour[g.particles[p]], -1);
        colour[g.particles[p]] = c;
      }
    for (int i = 0; i < m.num_particles(); ++i) ASSERT_GE(colour[i], 0);
    std::vector<char> coupled(g.colours(), 0);
    for (int k = 0; k < m.springs.size(); ++k) {
      const int a = m.springs.a[k], b = m.springs.b[k];
      if (colour[a] != colour[b]) continue;
      EXPECT_EQ(g.particle_class[a], g.particle_class[b]) << "spring " << k;
      coupled[colour[a]] = 1;
    }
    for (int c = 0; c < g.colours(); ++c) EXPECT_EQ(coupled[c], g.coupled[c]) << "colour " << c;
    const int last = n - 1;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          const int p = g.particle_class[cube_index(n, i, j, k)];
          EXPECT_EQ(p, g.particle_class[cube_index(n, last - i, j, k)]);
          EXPECT_EQ(p, g.particle_class[cube_index(n, i, last - j, k)]);
          EXPECT_EQ(p, g.particle_class[cube_index(n, i, j, last - k)]);
          EXPECT_EQ(p, g.particle_class[cube_index(n, j, k, i)]);
        }
    // The corners, the edges' inner particles, ... : the orbits of the cube's 48 symmetries.
    EXPECT_EQ(g.classes(), n == 4 ? 4 : 10);
    // Renumbering the particles renumbers the colouring: the same colours, particle for particle.
    Springs reversed = m.springs;
    const int last_particle = m.num_particles() - 1;
    for (int k = 0; k < reversed.size(); ++k) {
      reversed.a[k] = last_particle - m.springs.a[k];
      reversed.b[k] = last_particle - m.springs.b[k];
    }
    const VertexColouring r = colour_vertices(m.num_particles(), reversed);
    std::vector<int> colour_r(m.num_particles(), -1);
    for (int c = 0; c < r.colours(); ++c)
      for (int p = r.colour_start[c]; p < r.colour_start[c + 1]; ++p) colour_r[r.particles[p]] = c;
    for (int i = 0; i < m.num_particles(); ++i)
      EXPECT_EQ(colour[i], colour_r[last_particle - i]) << "particle " << i;
  }
}

State spinning(const Model& model, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(model);
  const Vec3 c = center_of_mass(model, s);
  for (int i = 0; i < model.num_particles(); ++i) {
    auto x = particle(s.x, i);
    for (int k = 0; k < 3; ++k) x[k] += 0.05 * u(rng);
    particle(s.v, i) = Vec3(0.2, -0.1, 0.3) + Vec3(0.5, 1.0, -0.3).cross(Vec3(x) - c);
  }
  return s;
}

// A free, deformed, spinning cube (no gravity, no contact) at a game step: each particle's
// Newton step moves only its own momentum, so the linear momentum is kept to the residual the
// sweeps leave of the step's force balance, which falls as the sweeps grow (the drift measured:
// docs/realtime.md; the registry's test checks 10 sweeps at dt = 1 ms). (Backward Euler itself
// damps the angular momentum.)
TEST(Vbd, FreeCubeKeepsItsMomentum) {
  CubeSpec spec = testing::small_cube(4);
  spec.gravity.setZero();
  const Model model = build_cube(spec);
  const State s0 = spinning(model, 5);
  const Vec3 p0 = linear_momentum(model, s0);
  std::vector<Real> drift;
  for (int iterations : {10, 60}) {
    VbdOptions o;
    o.iterations = iterations;
    Simulator sim = vbd_sim(model, s0, 1.0 / 60, o);
    ASSERT_TRUE(sim.run_until(1.0).ok());
    const Vec3 p1 = linear_momentum(model, sim.state());
    drift.push_back((p1 - p0).norm() / p0.norm());
  }
  EXPECT_LT(drift[0], 0.05);
  EXPECT_LT(drift[1], 1e-6);
}

// A cube hanging from its top face: the rest state of backward Euler (implicit_euler, Newton to
// convergence) is the static solution f(x) = 0. Started there, vbd stays there to within the
// residual its sweeps leave: each step starts from y = x + h^2 g, and `iterations` sweeps take
// back all but a fraction of that sag; the fraction shrinks as the iterations grow.
Model hanging_cube() {
  Model m = build_cube(testing::small_cube(4, 1.0, Vec3(0, 1, 0)));
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) {
      const int p = cube_index(4, i, 3, k);
      m.pins.add_fixed(p, Vec3(particle(m.rest_position, p)));
    }
  return m;
}

TEST(Vbd, HangingCubeStaysAtTheStaticSolution) {
  const Model m = hanging_cube();
  ImplicitEulerOptions newton;
  newton.newton_iterations = 50;
  newton.newton_tolerance = 1e-13;
  SimulatorOptions so;
  so.dt = 1.0 / 60;
  so.threads = 1;
  Simulator reference(m, rest_state(m), std::make_unique<ImplicitEuler>(newton), so);
  ASSERT_TRUE(reference.run_until(20.0).ok());
  State equilibrium = reference.state();
  equilibrium.t = 0;
  ASSERT_LT(testing::max_speed(equilibrium), 1e-9);
  // The sag of the static solution, the scale of the error.
  Real sag = 0;
  for (int i = 0; i < m.num_particles(); ++i)
    sag = std::max(sag,
                   (Vec3(particle(equilibrium.x, i)) - Vec3(particle(m.rest_position, i))).norm());
  ASSERT_GT(sag, 1e-3);
  std::vector<Real> errors;
  for (int iterations : {10, 40}) {
    VbdOptions o;
    o.iterations = iterations;
    Simulator sim = vbd_sim(m, equilibrium, 1.0 / 60, o);
    Real worst = 0;
    testing::Probe probe([&](const Simulator& s) {
      worst = std::max(worst, (s.state().x - equilibrium.x).lpNorm<Eigen::Infinity>());
    });
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(3.0).ok());
    errors.push_back(worst);
  }
  // The static solution is kept within 3 % of the sag with the default 10 iterations, and the
  // error shrinks with more: the rest state is backward Euler's, not a softer one. (The greedy
  // colouring in particle order kept 1 %: on this small cube the symmetric colouring's classes
  // are the lattice's symmetry classes, 4 of them, most of whose particles share springs and are
  // updated from the positions before their colour, docs/realtime.md.)
  EXPECT_LT(errors[0], 3e-2 * sag) << "sag " << sag;
  EXPECT_LT(errors[1], 0.5 * errors[0]) << "10 sweeps " << errors[0] << ", 40 sweeps " << errors[1];
}

// The seed cube at n = 20 dropped onto the coulomb slope at 1/60 s (it lands at about 11 m/s
// after 1.1 s). Returns the run's report, the lowest volume ratio of its cells over the frames,
// the most inverted cells and the deepest point below the slope.
struct ImpactOutcome {
  RunReport report;
  Real lowest_ratio = INFINITY, deepest = 0;
  int most_inverted = 0;
};
ImpactOutcome seed_cube_n20_impact(Real duration, Real contact_hardness) {
  CubeSpec spec;
  spec.n = 20;
  const Model model = build_cube(spec);
  SimulatorOptions so;
  so.dt = 1.0 / 60;
  so.threads = 1;
  IntegratorOptions o;
  o.vbd.contact_hardness = contact_hardness;
  Simulator sim(model, rest_state(model), make_integrator("vbd", o), so);
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
  const Terrain& slope = *sim.terrains()[0];
  ImpactOutcome out;
  testing::Probe probe([&](const Simulator& s) {
    const BodyVolume v = body_volume(s.model(), s.model().bodies[0], s.state().x);
    out.lowest_ratio = std::min(out.lowest_ratio, v.ratio());
    out.most_inverted = std::max(out.most_inverted, static_cast<int>(v.inverted));
    for (int i = 0; i < model.num_particles(); ++i)
      out.deepest = std::min(out.deepest, slope.signed_distance(particle(s.state().x, i), 0));
  });
  sim.add_observer(probe);
  out.report = sim.run_until(duration);
  return out;
}

// Through the impact vbd (10 sweeps, penalty contact of hardness 100) stays finite and on the
// slope (the penalty contact and the contact after the step leave no penetration), but the cube
// is crushed: the volume ratio fell to 0.22 (2,559 of 6,859 cells inverted; with the contact
// only after the step, the default, it turns inside out: -0.12; xpbd's default: 0.10, 3,111;
// implicit_euler: 0.67, 619, back to 0.93 at rest, docs/performance.md). Ten sweeps carry the
// contact only part of the way up a 20-layer jelly within the step.
TEST(Vbd, SeedCubeN20StaysFiniteThroughTheImpactAt1_60) {
  const ImpactOutcome out = seed_cube_n20_impact(1.5, 100);
  ASSERT_TRUE(out.report.ok()) << out.report.brief();
  EXPECT_GT(out.deepest, -1e-6);
  EXPECT_GT(out.lowest_ratio, 0.1);
}

// Issue 39's goal, not met (see above): the volume ratio above 0.8 through the impact.
TEST(Vbd, DISABLED_SeedCubeN20KeepsItsVolumeThroughTheImpactAt1_60) {
  const ImpactOutcome out = seed_cube_n20_impact(3.0, 100);
  ASSERT_TRUE(out.report.ok()) << out.report.brief();
  EXPECT_GT(out.lowest_ratio, 0.8);
  EXPECT_EQ(out.most_inverted, 0);
}

// Within a colour the particles are independent: 1, 2 and 3 threads give the same bits, with
// Chebyshev acceleration, Rayleigh damping, an anchor spring and a terrain.
TEST(Vbd, SameBitsOnAnyThreadCount) {
  CubeSpec spec = testing::small_cube(16, 1.0, Vec3(0, 0.3, 0));
  const Model model = build_cube(spec);
  // Colours large enough for a team of 3 (vbd.cpp: 128 particles per thread at least).
  ASSERT_GE(colour_vertices(model.num_particles(), model.springs).largest_colour(), 3 * 128);
  VbdOptions o;
  o.chebyshev_rho = 0.7;
  o.damping = 1e-3;
  std::vector<VecX> ends;
  for (int threads : {1, 2, 3}) {
    Simulator sim = vbd_sim(model, spinning(model, 9), 1.0 / 60, o, threads);
    sim.add_terrain(std::make_unique<Plane>(Vec3::Zero(), Vec3::UnitY()));
    sim.set_anchors({AnchorSpring{7, Vec3(0.2, 1.5, 0.1), 500, 5}});
    ASSERT_TRUE(sim.run_until(0.25).ok());
    ends.push_back(sim.state().x);
    ends.push_back(sim.state().v);
  }
  for (size_t k = 2; k < ends.size(); ++k) {
    ASSERT_EQ(ends[k].size(), ends[k % 2].size());
    EXPECT_EQ(0, std::memcmp(ends[k].data(), ends[k % 2].data(), ends[k].size() * sizeof(Real)))
        << "run " << k / 2 + 1;
  }
}

// Chebyshev acceleration brings a step closer to the backward-Euler step at equal iterations.
TEST(Vbd, ChebyshevAccelerates) {
  const Model m = build_cube(testing::small_cube(6));
  State s0 = spinning(m, 3);
  const Real h = 1.0 / 60;
  ImplicitEulerOptions newton;
  newton.newton_iterations = 100;
  newton.newton_tolerance = 1e-14;
  ImplicitEuler exact_integrator(newton);
  ContactSolver contacts;
  const Dynamics dynamics(m, contacts);
  State exact = s0;
  ASSERT_TRUE(exact_integrator.step(dynamics, exact, h).ok);
  auto error = [&](int iterations, Real rho) {
    VbdOptions o;
    o.iterations = iterations;
    o.chebyshev_rho = rho;
    Vbd vbd(o);
    State s = s0;
    EXPECT_TRUE(vbd.step(dynamics, s, h).ok);
    return (s.x - exact.x).norm();
  };
  // The plain sweeps' convergence factor per sweep, measured: the spectral radius Chebyshev
  // needs.
  const Real plain = error(20, 0);
  const Real rho = std::pow(plain / error(10, 0), 1.0 / 10);
  ASSERT_GT(rho, 0.1);
  ASSERT_LT(rho, 1);
  const Real accelerated = error(20, rho);
  EXPECT_LT(accelerated, 0.5 * plain) << plain << " " << accelerated << " rho " << rho;
}

// Invalid options are refused, naming the field, its value and what is allowed.
TEST(Vbd, InvalidOptionsNameTheField) {
  auto message = [](const VbdOptions& vbd) -> std::string {
    IntegratorOptions o;
    o.vbd = vbd;
    try {
      make_integrator("vbd", o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no InputError";
  };
  VbdOptions o;
  o.iterations = 0;
  EXPECT_NE(message(o).find("integrator.options.iterations = 0 is invalid"), std::string::npos)
      << message(o);
  o = {};
  o.chebyshev_rho = 1;
  EXPECT_NE(message(o).find("integrator.options.chebyshev_rho = 1 is invalid"), std::string::npos)
      << message(o);
  o = {};
  o.damping = -1;
  EXPECT_NE(message(o).find("integrator.options.damping = -1 is invalid"), std::string::npos)
      << message(o);
  o = {};
  o.chebyshev_rho = NAN;
  EXPECT_NE(message(o).find("integrator.options.chebyshev_rho"), std::string::npos);
  EXPECT_NO_THROW(make_integrator("vbd"));
}

// A cube stretched symmetrically about its centre and let go (no gravity, no terrain): the
// sweeps keep it symmetric under the three mirrors to round-off, so that its linear and angular
// momentum stay zero to 1e-12 (the greedy colouring in particle order lost the symmetry by
// millimetres), for few and many sweeps, with and without Chebyshev acceleration.
TEST(Vbd, StretchedCubeStaysSymmetric) {
  for (const auto& [iterations, rho] :
       {std::pair{2, 0.0}, std::pair{10, 0.0}, std::pair{10, 0.6}}) {
    SCOPED_TRACE(std::to_string(iterations) + " sweeps, rho " + std::to_string(rho));
    const int n = 5;
    const CubeSpec spec = testing::small_cube(n, 1.0, Vec3(-0.5, -0.5, -0.5));
    Model model = build_cube(spec);
    model.gravity.setZero();
    State s = rest_state(model);
    for (int i = 0; i < model.num_particles(); ++i) {
      const Vec3 p = particle(s.x, i);
      particle(s.x, i) = Vec3(1.4 * p.x(), 0.8 * p.y(), 1.1 * p.z());
    }
    VbdOptions o;
    o.iterations = iterations;
    o.chebyshev_rho = rho;
    Simulator sim = vbd_sim(model, s, 1.0 / 60, o);
    Real spin = 0, momentum = 0, asymmetry = 0;
    testing::Probe probe([&](const Simulator& sm) {
      spin = std::max(spin, angular_momentum(model, sm.state()).norm());
      momentum = std::max(momentum, linear_momentum(model, sm.state()).norm());
      const VecX& x = sm.state().x;
      const int l = n - 1;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < n; ++k) {
            const Vec3 p = particle(x, cube_index(n, i, j, k));
            const Vec3 mx = particle(x, cube_index(n, l - i, j, k));
            const Vec3 my = particle(x, cube_index(n, i, l - j, k));
            const Vec3 mz = particle(x, cube_index(n, i, j, l - k));
            asymmetry = std::max({asymmetry, (p - Vec3(-mx.x(), mx.y(), mx.z())).norm(),
                                  (p - Vec3(my.x(), -my.y(), my.z())).norm(),
                                  (p - Vec3(mz.x(), mz.y(), -mz.z())).norm()});
          }
    });
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(1.0).ok());
    // It moved: the stretch springs back.
    EXPECT_GT(kinetic_energy(model, sim.state()) + elastic_energy(model, sim.state()), 0);
    EXPECT_GT((sim.state().x - s.x).norm(), 0.1);
    const Real scale = model.mass.sum();  // kg m/s: the total mass at 1 m/s
    EXPECT_LT(spin, 1e-12 * scale);
    EXPECT_LT(momentum, 1e-12 * scale);
    EXPECT_LT(asymmetry, 1e-12);
    EXPECT_LT(center_of_mass(model, sim.state()).norm(), 1e-12);
  }
}

// The symmetric head-on collision stays symmetric at 1/240 and 1/60 s: particle (i, j, k) of the
// left cube is the mirror image of (3 - i, j, k) of the right one, positions and velocities to
// 1e-12; no sideways velocity, no spin, no net momentum. The colouring's classes span both
// cubes (an automorphism of the springs' graph swaps them), and at 1/60 s 1 and 2 threads give
// the same bits.
TEST(Vbd, MirroredCollisionStaysSymmetric) {
  for (const Real dt : {1.0 / 240, 1.0 / 60}) {
    SCOPED_TRACE(dt);
    Simulator sim = testing::head_on_cubes("vbd", dt);
    const Model& model = sim.model();
    long touching = 0;
    Real spin = 0, momentum = 0, asymmetry = 0;
    testing::Probe probe([&](const Simulator& sm) {
      touching += sm.body_contact().pairs().empty() ? 0 : 1;
      spin = std::max(spin, angular_momentum(model, sm.state()).norm());
      momentum = std::max(momentum, linear_momentum(model, sm.state()).norm());
      asymmetry = std::max(asymmetry, testing::head_on_asymmetry(sm.state()));
    });
    sim.add_observer(probe);
    ASSERT_TRUE(sim.run_until(0.5).ok());
    EXPECT_GT(touching, 0);
    const Real scale = model.mass.sum() * 2;  // kg m/s: total mass x approach speed
    EXPECT_LT(spin, 1e-12 * scale);
    EXPECT_LT(momentum, 1e-12 * scale);
    EXPECT_LT(asymmetry, 1e-12);
  }
  Simulator one = testing::head_on_cubes("vbd", 1.0 / 60, 0, 1),
            two = testing::head_on_cubes("vbd", 1.0 / 60, 0, 2);
  ASSERT_TRUE(one.run_until(0.3).ok());
  ASSERT_TRUE(two.run_until(0.3).ok());
  EXPECT_EQ(one.state().x, two.state().x);
  EXPECT_EQ(one.state().v, two.state().v);
}

}  // namespace
}  // namespace jelly
