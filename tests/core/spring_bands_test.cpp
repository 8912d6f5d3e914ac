// The vectorised force loop over spring bands computes the same forces as compute_forces.
#include <gtest/gtest.h>

#include <random>

#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/forces.hpp>
#include <jelly/geometry/cube.hpp>

#include "support/systems.hpp"

namespace jelly {
namespace {

State moving(const Model& m, unsigned seed, Real dx) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(m);
  for (int i = 0; i < s.x.size(); ++i) {
    s.x[i] += dx * u(rng);
    s.v[i] = u(rng);
  }
  return s;
}

// Largest |f_bands - f| relative to the largest |f|.
Real relative_difference(const Model& m, const SpringBands& bands, const State& s) {
  VecX f(m.num_dofs()), g(m.num_dofs());
  compute_forces(m, s.x, s.v, f);
  bands.compute_forces(m, s.x, s.v, g);
  return (f - g).cwiseAbs().maxCoeff() / f.cwiseAbs().maxCoeff();
}

class BandedCube : public ::testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(SpringBands, BandedCube, ::testing::Values(2, 3, 4, 10));

TEST_P(BandedCube, SameForcesAsComputeForces) {
  CubeSpec spec = testing::small_cube(GetParam());
  spec.springs[1] = {2500, 7};  // a different material per spring type
  const Model m = build_cube(spec);
  const SpringBands bands(m);
  ASSERT_TRUE(bands.dense());  // every cube spring sits in a band
  for (unsigned seed = 1; seed <= 3; ++seed)
    EXPECT_LT(relative_difference(m, bands, moving(m, seed, 0.1)), 1e-13) << seed;
}

// The slots a thread owning [p0, p1) computes.
long slots_touching(const SpringBands& bands, long p0, long p1) {
  long slots = 0;
  if (p0 >= p1) return 0;
  for (const SpringBands::Band& band : bands.bands()) {
    const SpringBands::Band::Reach r = band.reach(static_cast<int>(p0), static_cast<int>(p1));
    slots += std::max(0, r.hi - r.lo);
  }
  return slots;
}

// A thread also computes the slots crossing into its particles from below, so equal particle
// ranges give the middle threads more work (the first has no slots below, the last none
// above: two threads are even): at n = 20 the busiest of 3 threads computes 11 % more slots
// than the least busy, of 8 threads 29 %. The balanced ranges tile the particles and even the
// slots out to 0.2 %, and the forces stay the same bits.
TEST(SpringBands, ThreadRangesAreBalancedBySlots) {
  const Model m = build_cube(testing::small_cube(20));
  const SpringBands bands(m);
  const int n = m.num_particles();
  for (int parts : {2, 3, 8}) {
    const auto spread = [&](bool balanced) {
      if (balanced) bands.balance(parts);
      long most = 0, least = -1, next = 0;
      for (int part = 0; part < parts; ++part) {
        const parallel::Range r =
            balanced ? bands.thread_range(part, parts) : parallel::split(n, part, parts);
        EXPECT_EQ(r.begin, next) << parts;  // contiguous, in order
        next = r.end;
        const long slots = slots_touching(bands, r.begin, r.end);
        most = std::max(most, slots);
        least = least < 0 ? slots : std::min(least, slots);
      }
      EXPECT_EQ(next, n) << parts;
      return static_cast<Real>(most) / static_cast<Real>(least);
    };
    const Real uniform = spread(false), balanced = spread(true);
    EXPECT_LT(balanced, 1.01) << parts << " threads";
    if (parts > 2) {
      EXPECT_GT(uniform, 1.1) << parts << " threads";
    }
    // The forces do not depend on the split (tests/solvers/threads_test.cpp checks whole
    // trajectories for 1, 2 and 3 threads).
    const State s = moving(m, 7, 0.05);
    VecX f1(m.num_dofs()), fp(m.num_dofs());
    bands.compute_forces(m, s.x, s.v, f1, 1);
    bands.compute_forces(m, s.x, s.v, fp, parts);
    EXPECT_EQ(f1, fp) << parts << " threads";
  }
}

// Two particles projected onto one point: compute_forces pushes along the rest direction, and so
// does the banded loop (by falling back to it).
TEST(SpringBands, CollapsedSpringFallsBackToTheRestDirection) {
  const Model m = build_cube(testing::small_cube(2));
  const SpringBands bands(m);
  State s = rest_state(m);
  particle(s.x, 1) = particle(s.x, 0);
  VecX f(m.num_dofs()), g(m.num_dofs());
  compute_forces(m, s.x, s.v, f);
  bands.compute_forces(m, s.x, s.v, g);
  EXPECT_TRUE(g.allFinite());
  EXPECT_EQ(f, g);
}

// Springs that do not fill bands (here: 3 springs spread over offsets 1 ... 500) are evaluated
// by compute_forces itself.
TEST(SpringBands, SparseTopologyUsesComputeForces) {
  Model m;
  m.mass = VecX::Constant(501, 1.0);
  m.rest_position = VecX::Zero(3 * 501);
  for (int i = 0; i < 501; ++i) m.rest_position[3 * i] = i;
  m.springs.add(0, 1, 1, {100, 1}, SpringType::kStructural);
  m.springs.add(0, 500, 500, {100, 1}, SpringType::kStructural);
  m.springs.add(7, 200, 193, {100, 1}, SpringType::kStructural);
  m.springs.add(300, 400, 100, {100, 1}, SpringType::kStructural);
  const SpringBands bands(m);
  EXPECT_FALSE(bands.dense());
  const State s = moving(m, 5, 0.1);
  VecX f(m.num_dofs()), g(m.num_dofs());
  compute_forces(m, s.x, s.v, f);
  bands.compute_forces(m, s.x, s.v, g);
  EXPECT_EQ(f, g);
}

}  // namespace
}  // namespace jelly
