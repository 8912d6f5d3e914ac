// The seed scenes give bit for bit the trajectories they gave before the model held bodies:
// the states at t = 2 s equal those of recordings made with jelly 0.1.0 at commit c6f30bd
// (`jelly run SCENE --duration 2 --set output_interval=0.5 ...`, last frame), compared through
// a 64-bit FNV-1a hash of the bytes of x and v (little-endian doubles). implicit_euler's hash
// was renewed when its solve became matrix-free and threaded (issue 17: other summation orders,
// a rounding-level change; its first particle is where it was to 1e-7), and again when its CG
// tolerance became 1e-5, the product's terms were stored as two numbers and the block-Jacobi
// inverses as floats (the first particle still within 1e-7), and when the matrix-free product's
// two coefficients per spring became floats at the default cg_tolerance (likewise).
#include <cstdint>
#include <cstring>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <jelly/io/scene.hpp>

namespace jelly {
namespace {

std::uint64_t fnv1a(const VecX& x, const VecX& v) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const VecX* w : {&x, &v}) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(w->data());
    for (std::size_t i = 0; i < sizeof(double) * static_cast<std::size_t>(w->size()); ++i) {
      h ^= bytes[i];
      h *= 0x100000001b3ULL;
    }
  }
  return h;
}

struct Reference {
  const char* scene;
  std::vector<std::string> overrides;
  std::uint64_t hash;
  Vec3 first_particle;  // printed to 8 digits, for a readable failure
};

// The test's name in ctest: the scene and its overrides (gtest would print the bytes of the
// struct, a pointer among them, and the name would change from build to build).
void PrintTo(const Reference& r, std::ostream* out) {
  *out << r.scene;
  for (const std::string& o : r.overrides) *out << ' ' << o;
}

class SeedReference : public ::testing::TestWithParam<Reference> {};

TEST_P(SeedReference, StateAtTwoSecondsIsBitForBitTheSame) {
  const Reference& r = GetParam();
  std::vector<std::string> overrides = r.overrides;
  overrides.push_back("output_interval=0.5");
  const Scene scene = load_scene(std::string(JELLY_SCENES_DIR) + "/" + r.scene, overrides);
  Simulator sim = make_simulator(scene);
  ASSERT_TRUE(sim.run_until(2.0).ok());
  EXPECT_LT((sim.state().x.segment<3>(0) - r.first_particle).norm(), 1e-7);
  EXPECT_EQ(fnv1a(sim.state().x, sim.state().v), r.hash);
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, SeedReference,
    ::testing::Values(
        Reference{
            "seed_slope.json", {}, 0x2ccd44d5bb1f1b0ULL, Vec3(0.4249714, 2.70028936, -2.22025917)},
        Reference{"seed_elevator.json",
                  {},
                  0x8744086d10ea730ULL,
                  Vec3(-2.24047018, 7.00606025, -2.24047018)},
        Reference{"drop_coulomb.json",
                  {"integrator.name=implicit_euler", "integrator.dt=0.016666666666666666"},
                  0x71fc0c1851d665c0ULL,
                  Vec3(-0.99997102, 0, -0.99997102)},
        // The same run without contact screening: the same bits (docs/implicit.md).
        Reference{"drop_coulomb.json",
                  {"integrator.name=implicit_euler", "integrator.dt=0.016666666666666666",
                   "integrator.options.contact_screening_tolerance=0"},
                  0x71fc0c1851d665c0ULL,
                  Vec3(-0.99997102, 0, -0.99997102)},
        Reference{"seed_slope.json",
                  {"integrator.name=symplectic_euler", "terrains.0.contact.model=coulomb"},
                  0xc6628f28dc3786fbULL,
                  Vec3(0.32279717, 2.86131441, -2.22061873)}));

}  // namespace
}  // namespace jelly
