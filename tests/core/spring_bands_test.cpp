// The vectorised force loop over spring bands computes the same forces as compute_forces.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
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

// A band whose springs share ks and kd reads them once (uniform). One spring with its own kd makes
// its band read per slot again: with both ends of that spring at rest its damper adds nothing, so
// the forces must be the uniform band's, bit for bit, and they stay those of compute_forces.
TEST(SpringBands, UniformBandsGiveTheBitsOfPerSlotCoefficients) {
  CubeSpec spec = testing::small_cube(6);
  spec.springs[1] = {2500, 7};
  const Model uniform_model = build_cube(spec);
  const SpringBands uniform(uniform_model);
  for (const SpringBands::Band& band : uniform.bands()) EXPECT_TRUE(band.uniform) << band.offset;
  Model mixed_model = uniform_model;
  const int spring = 10;
  mixed_model.springs.kd[spring] *= 2;
  const SpringBands mixed(mixed_model);
  int per_slot = 0;
  for (const SpringBands::Band& band : mixed.bands()) per_slot += !band.uniform;
  EXPECT_EQ(per_slot, 1);
  for (unsigned seed = 1; seed <= 3; ++seed) {
    State s = moving(uniform_model, seed, 0.1);
    particle(s.v, uniform_model.springs.a[spring]).setZero();
    particle(s.v, uniform_model.springs.b[spring]).setZero();
    VecX f(uniform_model.num_dofs()), g(uniform_model.num_dofs());
    uniform.compute_forces(uniform_model, s.x, s.v, f);
    mixed.compute_forces(mixed_model, s.x, s.v, g);
    EXPECT_TRUE(f == g) << seed;
    EXPECT_LT(relative_difference(mixed_model, mixed, s), 1e-13) << seed;
  }
}

// The threads split the particles (a cube of 14^3 particles, 37,000 springs: up to 4 threads);
// every split gives the same bits, and compute_accelerations is compute_forces times 1 / m.
TEST(SpringBands, ThreadsAndAccelerationsGiveTheSameBits) {
  const Model m = build_cube(testing::small_cube(14));
  const SpringBands bands(m);
  ASSERT_TRUE(bands.dense());
  const State s = moving(m, 7, 0.05);
  VecX f1(m.num_dofs());
  bands.compute_forces(m, s.x, s.v, f1, 1);
  EXPECT_LT(relative_difference(m, bands, s), 1e-13);
  VecX a1 = f1;
  for (int i = 0; i < m.num_particles(); ++i) {
    const Real inv = 1.0 / m.mass[i];
    for (int d = 0; d < 3; ++d) a1[3 * i + d] *= inv;
  }
  for (int threads : {1, 2, 3, 4}) {
    VecX f(m.num_dofs()), a(m.num_dofs());
    bands.compute_forces(m, s.x, s.v, f, threads);
    bands.compute_accelerations(m, s.x, s.v, a, threads);
    EXPECT_TRUE(f == f1) << threads << " threads";
    EXPECT_TRUE(a == a1) << threads << " threads";
  }
}

// Terms added inside the force loop (the seed contact forces use this): each particle's terms
// are added once, by the thread that owns it, to its finished sum and before the division by the
// mass: the same bits as adding them to compute_forces' result and dividing, for any split.
class EverySeventhParticle final : public SpringBands::RangeTerms {
 public:
  explicit EverySeventhParticle(int particles) : calls_(particles, 0) {}
  void add(int begin, int end, VecX& f) const override {
    for (int i = begin; i < end; ++i) {
      ++calls_[i];
      if (i % 7 != 0) continue;
      // Depends on the sum it is added to, as the contact force does.
      for (int d = 0; d < 3; ++d) f[3 * i + d] += -0.5 * f[3 * i + d] + 1e-3 * (i + d);
    }
  }
  std::vector<int>& calls() const { return calls_; }

 private:
  mutable std::vector<int> calls_;
};

TEST(SpringBands, TermsAddedByEachThreadGiveTheSameBits) {
  const Model m = build_cube(testing::small_cube(14));
  const SpringBands bands(m);
  ASSERT_TRUE(bands.dense());
  const State s = moving(m, 5, 0.05);
  const EverySeventhParticle terms(m.num_particles());
  VecX expected(m.num_dofs());
  bands.compute_forces(m, s.x, s.v, expected, 1);
  terms.add(0, m.num_particles(), expected);
  divide_by_masses(m, expected);
  for (int threads : {1, 2, 3, 4}) {
    std::fill(terms.calls().begin(), terms.calls().end(), 0);
    VecX a(m.num_dofs());
    bands.compute_accelerations(m, s.x, s.v, a, threads, &terms);
    EXPECT_TRUE(a == expected) << threads << " threads";
    EXPECT_EQ(std::count(terms.calls().begin(), terms.calls().end(), 1), m.num_particles())
        << threads << " threads: every particle's terms added once";
  }
  // A collapsed spring: the serial loop's forces, then the terms, then the division.
  State collapsed = s;
  const int last = m.num_particles() - 1;
  particle(collapsed.x, last) = particle(collapsed.x, last - 1);
  compute_forces(m, collapsed.x, collapsed.v, expected);
  terms.add(0, m.num_particles(), expected);
  divide_by_masses(m, expected);
  for (int threads : {1, 3}) {
    VecX a(m.num_dofs());
    bands.compute_accelerations(m, collapsed.x, collapsed.v, a, threads, &terms);
    EXPECT_TRUE(a == expected) << threads << " threads, collapsed";
  }
}

// OpenMP may start fewer threads than asked (here none: inside SerialLibraries a region gets a
// team of one): the one thread then owns every particle, its workspace grows to match, and the
// threads of an earlier, larger team (one of which saw a collapsed spring) are not consulted.
TEST(SpringBands, FewerThreadsThanAskedGiveTheSameBits) {
  const Model m = build_cube(testing::small_cube(14));
  const SpringBands bands(m);
  const State s = moving(m, 3, 0.05);
  VecX f1(m.num_dofs()), f(m.num_dofs());
  bands.compute_forces(m, s.x, s.v, f1, 1);
  State collapsed = s;
  const int last = m.num_particles() - 1;
  particle(collapsed.x, last) = particle(collapsed.x, last - 1);  // in the last thread's range
  bands.compute_forces(m, collapsed.x, collapsed.v, f, 4);
  {
    const parallel::SerialLibraries one_thread;
    bands.compute_forces(m, s.x, s.v, f, 4);
  }
  EXPECT_TRUE(f == f1);
  bands.compute_forces(m, s.x, s.v, f, 4);
  EXPECT_TRUE(f == f1);
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
