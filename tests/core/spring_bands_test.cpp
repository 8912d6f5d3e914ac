// The vectorised force loop over spring bands computes the same forces as compute_forces.
#include <gtest/gtest.h>

#include <random>

#include <jelly/geometry/cube.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/forces.hpp>

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
