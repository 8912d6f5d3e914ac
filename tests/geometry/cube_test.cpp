#include <gtest/gtest.h>

#include <ostream>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>

namespace jelly {
namespace {

struct Counts {
  int n, structural, shear, bending;
};

// (For ctest's test names: gtest prints a struct without PrintTo as its bytes.)
void PrintTo(const Counts& c, std::ostream* os) { *os << "n = " << c.n; }

class CubeCounts : public ::testing::TestWithParam<Counts> {};

TEST_P(CubeCounts, SpringsPerType) {
  const Counts c = GetParam();
  CubeSpec spec;
  spec.n = c.n;
  const Model m = build_cube(spec);
  EXPECT_EQ(m.num_particles(), c.n * c.n * c.n);
  EXPECT_EQ(m.springs.count(SpringType::kStructural), c.structural);
  EXPECT_EQ(m.springs.count(SpringType::kShear), c.shear);
  EXPECT_EQ(m.springs.count(SpringType::kBending), c.bending);
  EXPECT_EQ(m.springs.size(), c.structural + c.shear + c.bending);
}

// structural 3 n^2 (n-1); shear 6 n (n-1)^2 + 4 (n-1)^3; bending 3 n^2 (n-2).
INSTANTIATE_TEST_SUITE_P(Seed, CubeCounts,
                         ::testing::Values(Counts{2, 12, 6 * 2 + 4, 0}, Counts{3, 54, 72 + 32, 27},
                                           Counts{10, 2700, 7776, 2400}),
                         [](const ::testing::TestParamInfo<Counts>& p) {
                           return "n" + std::to_string(p.param.n);
                         });

TEST(Cube, SeedPoseAndRestLengths) {
  const Model m = build_cube(CubeSpec{});
  ASSERT_EQ(m.springs.size(), 12876);
  const Vec3 com = center_of_mass(m, m.rest_position);
  EXPECT_NEAR(com.x(), -0.2222, 1e-4);
  EXPECT_NEAR(com.y(), 8.7778, 1e-4);
  EXPECT_NEAR(com.z(), -0.2222, 1e-4);
  const Real h = 4.0 / 9;
  for (int s = 0; s < m.springs.size(); ++s) {
    const Real expected = m.springs.type[s] == SpringType::kStructural ? h
                          : m.springs.type[s] == SpringType::kBending  ? 2 * h
                                                                       : -1;
    if (expected > 0) {
      EXPECT_NEAR(m.springs.rest_length[s], expected, 1e-12);
    } else {
      const Real l = m.springs.rest_length[s];
      EXPECT_TRUE(std::abs(l - std::sqrt(2.0) * h) < 1e-12 ||
                  std::abs(l - std::sqrt(3.0) * h) < 1e-12);
    }
    EXPECT_EQ(m.springs.ks[s], 1400);
    EXPECT_EQ(m.springs.kd[s], 50);
  }
  const State s = rest_state(m);
  EXPECT_EQ(s.v.norm(), 0);
  EXPECT_EQ(elastic_energy(m, s), 0);
}

TEST(Cube, PerTypeCoefficients) {
  CubeSpec spec;
  spec.n = 3;
  spec.springs = {SpringCoefficients{1000, 1}, SpringCoefficients{1500, 2},
                  SpringCoefficients{800, 3}};
  const Model m = build_cube(spec);
  for (int s = 0; s < m.springs.size(); ++s) {
    const int t = static_cast<int>(m.springs.type[s]);
    EXPECT_EQ(m.springs.ks[s], spec.springs[t].ks);
    EXPECT_EQ(m.springs.kd[s], spec.springs[t].kd);
  }
}

std::string error_of(const CubeSpec& spec) {
  try {
    build_cube(spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Cube, BadInputNamesFieldValueAndRange) {
  CubeSpec spec;
  spec.n = 1;
  EXPECT_EQ(error_of(spec), "cube.n = 1 is invalid: an integer in [2, 400]");
  spec = CubeSpec{};
  spec.edge_length = -4;
  EXPECT_EQ(error_of(spec), "cube.edge_length = -4 is invalid: a finite length > 0");
  spec = CubeSpec{};
  spec.particle_mass = 0;
  EXPECT_EQ(error_of(spec), "cube.particle_mass = 0 is invalid: a finite mass > 0");
  spec = CubeSpec{};
  spec.springs[1].ks = -1;
  EXPECT_EQ(error_of(spec), "springs.shear.ks = -1 is invalid: a finite stiffness >= 0");
  spec = CubeSpec{};
  spec.springs[2].kd = std::nan("");
  EXPECT_NE(error_of(spec).find("springs.bending.kd = nan"), std::string::npos);
}

}  // namespace
}  // namespace jelly
