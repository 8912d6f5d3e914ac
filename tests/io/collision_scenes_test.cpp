// The collision scenes of issue 13 run as shipped: scenes/folding_strip.json folds onto itself
// without ever self-penetrating; in scenes/bear_in_bowl.json the bears come to rest in the bowl.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <jelly/core/measures.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/contact/detail/broad_phase.hpp>
#include <jelly/terrain/detail/mesh_obstacle.hpp>

#include "scene_files.hpp"
#include "support/systems.hpp"

namespace jelly {
namespace {

using testing::scene_path;

// The pairs of particles no spring joins that are closer than `fraction` of their radii's sum.
class CloseNonNeighbours {
 public:
  CloseNonNeighbours(const Model& m, Real fraction) : radius_(m.num_particles()) {
    for (const Body& b : m.bodies)
      for (int i = b.first_particle; i < b.end_particle(); ++i) radius_[i] = fraction * b.radius;
    for (int s = 0; s < m.springs.size(); ++s) {
      const auto [i, j] = std::minmax(m.springs.a[s], m.springs.b[s]);
      joined_.insert({i, j});
    }
  }
  // How many there are in `x`; the closest one's distance over the radii's sum goes to `worst`.
  int count(const Model& m, const VecX& x, Real& worst) {
    broad_.find_pairs(x, radius_, pairs_);
    int n = 0;
    for (const auto& [i, j] : pairs_) {
      if (joined_.count({std::min(i, j), std::max(i, j)}) > 0) continue;
      ++n;
      worst = std::min(worst, (particle(x, i) - particle(x, j)).norm() /
                                  (m.body_of(i).radius + m.body_of(j).radius));
    }
    return n;
  }

 private:
  VecX radius_;
  std::set<std::pair<int, int>> joined_;
  BroadPhase broad_;
  std::vector<BroadPhase::Pair> pairs_;
};

// The strip lands on the step, folds onto itself and rests there folded: at no step are two
// particles that no spring joins closer than the sum of their radii less 1 %, though self-contact
// is busy (it resolved pairs at most steps after the landing, and the folded strip is several
// layers thick on the step).
TEST(CollisionScenes, FoldingStripNeverSelfPenetrates) {
  const Scene scene = load_scene(scene_path("folding_strip.json"));
  ASSERT_TRUE(scene.body_contact.self_contact);
  Simulator sim = make_simulator(scene);
  const Model& m = sim.model();
  CloseNonNeighbours penetrating(m, 0.99);
  CloseNonNeighbours touching(m, 1.001);
  Real worst = 1e9, ignored = 1e9;
  long penetrations = 0, steps_in_contact = 0;
  Vec3 com_at_3 = Vec3::Zero();
  while (sim.state().t < scene.duration - 0.5 * scene.integrator.dt) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << r.message;
    if (std::abs(sim.state().t - 3.0) < 0.5 * scene.integrator.dt)
      com_at_3 = center_of_mass(m, sim.state());
    penetrations += penetrating.count(m, sim.state().x, worst);
    steps_in_contact += touching.count(m, sim.state().x, ignored) > 0;
  }
  EXPECT_EQ(penetrations, 0) << "closest non-neighbours at " << worst << " of their radii's sum";
  EXPECT_GT(worst, 0.99);
  EXPECT_GT(steps_in_contact, 1000);  // of 8000: folded, not merely lying flat
  // At rest, folded on the step: some particle at least three layers (0.3 m) above its top, the
  // centre of mass still in the last second (single particles in self-contact keep a buzz of a
  // few tenths of a m/s, as the stack's do: docs/contact.md).
  Real highest = -1e9;
  for (int i = 0; i < m.num_particles(); ++i) highest = std::max(highest, sim.state().x[3 * i + 1]);
  EXPECT_GT(highest, 0.5 + 0.3);
  EXPECT_LT((center_of_mass(m, sim.state()) - com_at_3).norm(), 0.01);
}

// The three bears fall into the bowl (a mesh obstacle), pile at its bottom and come to rest: in
// the last second no bear's centre moves 1 cm; at every frame no particle is more than 1 mm
// inside the bowl's mesh, and at the end every particle is in the bowl (below its rim, inside
// its inner radius).
TEST(CollisionScenes, BearsComeToRestInTheBowl) {
  const Scene scene = load_scene(scene_path("bear_in_bowl.json"));
  Simulator sim = make_simulator(scene);
  const Model& m = sim.model();
  ASSERT_EQ(m.num_bodies(), 3);
  const auto& bowl = dynamic_cast<const MeshObstacle&>(*sim.terrains().at(1));
  const Real scale = bowl.spec().pose.scale;
  // assets/bowl.obj: inner radius 0.36, rim at y = 0.4, centred on the y axis.
  const Real inner_radius = 0.36 * scale, rim = 0.4 * scale;
  Real deepest = 0;
  testing::Probe probe([&](const Simulator& s) {
    for (int i = 0; i < m.num_particles(); ++i)
      deepest = std::min(deepest, bowl.signed_distance(particle(s.state().x, i), s.state().t));
  });
  sim.add_observer(probe);
  const auto centres = [&] {
    std::vector<Vec3> c;
    for (const Body& b : m.bodies) {
      Vec3 sum = Vec3::Zero();
      for (int i = b.first_particle; i < b.end_particle(); ++i) sum += particle(sim.state().x, i);
      c.push_back(sum / b.num_particles);
    }
    return c;
  };
  ASSERT_TRUE(sim.run_until(scene.duration - 1).ok());
  const std::vector<Vec3> before = centres();
  ASSERT_TRUE(sim.run_until(scene.duration).ok());
  const std::vector<Vec3> after = centres();
  for (int b = 0; b < 3; ++b) EXPECT_LT((after[b] - before[b]).norm(), 0.01) << b;
  EXPECT_GE(deepest, -1e-3);
  for (int i = 0; i < m.num_particles(); ++i) {
    const Vec3 x = particle(sim.state().x, i);
    EXPECT_LT(x.y(), rim) << i;
    EXPECT_LT(std::hypot(x.x(), x.z()), inner_radius) << i;
  }
}

}  // namespace
}  // namespace jelly
