// Broad and narrow phase of body-body contact (docs/contact.md, "What contact costs"): two n^3
// cubes side by side, their facing layers overlapping by 1 % of the contact distance (n^2
// contact pairs), one BodyContact::resolve per iteration on a fresh copy of the state (the copy
// is not timed), alone or after the collision phase (BodyContact::collide). Counters: particles,
// pairs, ns per particle, and the broad phase alone. Run on one core: taskset -c 0
// build/bench/jelly_contact_benchmark (the manual times and the
// *_ms counters are wall clock; on a shared machine read the CPU column).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/jelly.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/broad_phase.hpp>
#include <jelly/terrain/detail/mesh_obstacle.hpp>

namespace {

using namespace jelly;

Model two_cubes(int n) {
  const Real edge = 4, spacing = edge / (n - 1);
  Model model;
  CubeSpec a;
  a.n = n;
  a.edge_length = edge;
  a.origin = Vec3(0, 0, 0);
  CubeSpec b = a;
  b.origin = Vec3(edge + 0.99 * spacing, 0, 0);  // facing layers 1 % inside each other
  model.add_body("a", a.shape().build(a.material(), "a."));
  model.add_body("b", b.shape().build(b.material(), "b."));
  return model;
}

// One step's body contact; `collide`: with the collision phase before the step
// (BodyContact::collide, as the Simulator runs it; resolve() then takes its pairs from that set)
// rather than resolve()'s own search.
void body_contact_step(benchmark::State& bench, bool collide) {
  const Model model = two_cubes(static_cast<int>(bench.range(0)));
  const State start = rest_state(model);
  BodyContact contact;
  State s = start;
  size_t pairs = 0;
  for (auto _ : bench) {
    s.x = start.x;
    s.v = start.v;
    const auto t0 = std::chrono::steady_clock::now();
    if (collide) contact.collide(model, start, 1e-3);
    contact.resolve(model, start, s, 1e-3);
    const auto t1 = std::chrono::steady_clock::now();
    pairs = contact.pairs().size();
    bench.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  const double steps = static_cast<double>(contact.stats().steps);
  bench.counters["particles"] = model.num_particles();
  bench.counters["pairs"] = static_cast<double>(pairs);
  bench.counters["broad_ms"] = 1e3 * contact.stats().broad_seconds / steps;
  bench.counters["narrow_ms"] = 1e3 * contact.stats().narrow_seconds / steps;
  bench.counters["ns_per_particle"] =
      1e9 * (contact.stats().broad_seconds + contact.stats().narrow_seconds) / steps /
      model.num_particles();
}
void BM_BodyContactResolve(benchmark::State& bench) { body_contact_step(bench, false); }
void BM_BodyContactCollideAndResolve(benchmark::State& bench) { body_contact_step(bench, true); }
BENCHMARK(BM_BodyContactResolve)
    ->Arg(10)
    ->Arg(20)
    ->Arg(30)
    ->Arg(32)
    ->Arg(40)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BodyContactCollideAndResolve)
    ->Arg(10)
    ->Arg(20)
    ->Arg(40)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The broad phase alone on one n^3 cube (n = 40: 64,000 particles).
void BM_BroadPhaseOneCube(benchmark::State& bench) {
  CubeSpec spec;
  spec.n = static_cast<int>(bench.range(0));
  const Model model = build_cube(spec);
  const State s = rest_state(model);
  const VecX radius = VecX::Constant(model.num_particles(), 0.5 * 4.0 / (spec.n - 1));
  BroadPhase broad;
  std::vector<BroadPhase::Pair> pairs;
  for (auto _ : bench) {
    broad.find_pairs(s.x, radius, pairs);
    benchmark::DoNotOptimize(pairs.data());
  }
  bench.counters["particles"] = model.num_particles();
  bench.counters["pairs"] = static_cast<double>(pairs.size());
}
BENCHMARK(BM_BroadPhaseOneCube)->Arg(10)->Arg(20)->Arg(40)->Unit(benchmark::kMillisecond);

// One particle's query of a mesh obstacle (signed distance, normal and surface velocity, as the
// coulomb contact asks them: one search), on a sphere mesh of 2 r^2 triangles (r = the argument,
// the rings), for the particles of a 20^3 lattice filling the sphere's bounding box (1.2 times
// larger): 30 % inside, the rest up to 1.1 radii outside. Counter: CPU time per query.
void BM_MeshObstacleQuery(benchmark::State& bench) {
  const int rings = static_cast<int>(bench.range(0));
  const std::string file = "/tmp/jelly_contact_benchmark_sphere_" + std::to_string(rings) + ".stl";
  write_mesh(file, sphere_mesh(1.0, rings, 2 * rings));
  MeshObstacleSpec spec;
  spec.file = file;
  const MeshObstacle mesh(spec);
  std::remove(file.c_str());
  std::vector<Vec3> points;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 20; ++k) points.push_back(1.2 * (Vec3(i, j, k) / 9.5 - Vec3::Ones()));
  Real sum = 0;
  for (auto _ : bench) {
    for (const Vec3& p : points) {
      sum += mesh.signed_distance(p, 0);
      sum += mesh.normal(p, 0).x();
      sum += mesh.surface_velocity(p, 0).x();
    }
  }
  benchmark::DoNotOptimize(sum);
  bench.counters["triangles"] = mesh.shape().distance.mesh().num_triangles();
  // Seconds of CPU per query (printed with an SI prefix: 500n = 500 ns).
  bench.counters["per_query"] = benchmark::Counter(
      static_cast<double>(points.size()) * static_cast<double>(bench.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MeshObstacleQuery)->Arg(16)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
