// Scene files carry the options of projective_dynamics, xpbd and vbd (docs/scenes.md).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {
namespace {

const char* const kScene = R"({
  "terrains": [{"kind": "slope"}],
  "integrator": {"name": "rk4"},
  "duration": 1
})";

TEST(SceneRealtimeOptions, RoundTrip) {
  const Scene pd =
      parse_scene(kScene, {"integrator.name=projective_dynamics", "integrator.options.iterations=7",
                           "integrator.options.chebyshev=true", "integrator.options.tolerance=1e-6",
                           "integrator.options.ordering=\"amd\""});
  EXPECT_EQ(pd.integrator.options.pd.iterations, 7);
  EXPECT_TRUE(pd.integrator.options.pd.chebyshev);
  const Scene pd_again = parse_scene(scene_to_json(pd));
  EXPECT_EQ(pd_again.integrator.options.pd.iterations, 7);
  EXPECT_EQ(pd_again.integrator.options.pd.tolerance, 1e-6);
  EXPECT_EQ(pd_again.integrator.options.pd.ordering, CholmodOrdering::kAmd);
  EXPECT_NO_THROW(make_simulator(pd));

  const Scene xpbd = parse_scene(
      kScene, {"integrator.name=xpbd", "integrator.options.substeps=8",
               "integrator.options.iterations=1", "integrator.options.contact=\"after_step\""});
  const Scene xpbd_again = parse_scene(scene_to_json(xpbd));
  EXPECT_EQ(xpbd_again.integrator.options.xpbd.substeps, 8);
  EXPECT_EQ(xpbd_again.integrator.options.xpbd.iterations, 1);
  EXPECT_EQ(xpbd_again.integrator.options.xpbd.contact, PositionContactMode::kAfterStep);
  EXPECT_NO_THROW(make_simulator(xpbd));

  const Scene vbd = parse_scene(
      kScene, {"integrator.name=vbd", "integrator.options.iterations=15",
               "integrator.options.chebyshev_rho=0.8", "integrator.options.damping=0.01",
               "integrator.options.contact_hardness=50"});
  const Scene vbd_again = parse_scene(scene_to_json(vbd));
  EXPECT_EQ(vbd_again.integrator.options.vbd.iterations, 15);
  EXPECT_EQ(vbd_again.integrator.options.vbd.chebyshev_rho, 0.8);
  EXPECT_EQ(vbd_again.integrator.options.vbd.damping, 0.01);
  EXPECT_EQ(vbd_again.integrator.options.vbd.contact_hardness, 50);
  EXPECT_NO_THROW(make_simulator(vbd));
}

TEST(SceneRealtimeOptions, BadOptionsNameTheirPath) {
  try {
    parse_scene(kScene, {"integrator.name=xpbd", "integrator.options.substeps=0"});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::StartsWith("integrator.options.substeps = 0 is invalid"));
  }
  // Named choices come from their enum tables (core/errors.hpp): the message lists them.
  try {
    parse_scene(kScene,
                {"integrator.name=projective_dynamics", "integrator.options.contact=\"implicit\""});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(
        e.what(),
        ::testing::StartsWith(
            R"(integrator.options.contact = "implicit" is invalid: one of "projection", "after_step")"));
  }
  try {
    parse_scene(kScene,
                {"integrator.name=projective_dynamics", "integrator.options.ordering=\"colamd\""});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(
        e.what(),
        ::testing::StartsWith(
            R"(integrator.options.ordering = "colamd" is invalid: one of "amd", "metis", "nesdis", "best")"));
  }
  EXPECT_THROW(parse_scene(kScene, {"integrator.name=xpbd", "integrator.options.contact=\"x\""}),
               InputError);
  try {
    parse_scene(kScene, {"integrator.name=vbd", "integrator.options.chebyshev_rho=1.5"});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(),
                ::testing::StartsWith("integrator.options.chebyshev_rho = 1.5 is invalid"));
  }
  EXPECT_THROW(parse_scene(kScene, {"integrator.name=vbd", "integrator.options.substeps=2"}),
               InputError);
  // substeps belongs to xpbd, not to projective_dynamics.
  EXPECT_THROW(
      parse_scene(kScene, {"integrator.name=projective_dynamics", "integrator.options.substeps=2"}),
      InputError);
}

}  // namespace
}  // namespace jelly

namespace jelly {
namespace {

// xpbd's sweep and the crush limits read, written back and validated with the field named.
TEST(SceneRealtimeOptions, XpbdSweepAndCrushLimits) {
  const char* const scene = R"({
    "integrator": {"name": "xpbd", "options": {"sweep": "gauss_seidel"}},
    "crush": {"min_volume_ratio": 0.25, "max_inverted_fraction": 0.5},
    "duration": 1
  })";
  const Scene s = parse_scene(scene);
  EXPECT_EQ(s.integrator.options.xpbd.sweep, XpbdSweep::kGaussSeidel);
  EXPECT_EQ(s.crush.min_volume_ratio, 0.25);
  const Scene again = parse_scene(scene_to_json(s));
  EXPECT_EQ(again.integrator.options.xpbd.sweep, XpbdSweep::kGaussSeidel);
  EXPECT_EQ(again.crush.max_inverted_fraction, 0.5);
  // The defaults are not written.
  EXPECT_EQ(scene_to_json(parse_scene(kScene)).find("crush"), std::string::npos);
  try {
    parse_scene(scene, {"integrator.options.sweep=\"random\""});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("integrator.options.sweep"));
  }
  try {
    parse_scene(scene, {"crush.max_inverted_fraction=2"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "crush.max_inverted_fraction = 2 is invalid: a number in [0, 1] (1: "
                 "never by inverted cells)");
  }
}

}  // namespace
}  // namespace jelly
