// Micro-benchmarks of the hot loop: the seed cube's force evaluation and one step of each
// integrator on the seed slope (contact included).
#include <benchmark/benchmark.h>

#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/jelly.hpp>

namespace {

using namespace jelly;

void BM_ComputeForces(benchmark::State& bench) {
  CubeSpec spec;
  spec.n = static_cast<int>(bench.range(0));
  const Model model = build_cube(spec);
  State s = rest_state(model);
  for (int i = 0; i < s.x.size(); ++i) s.x[i] += 1e-3 * std::sin(0.37 * i);
  VecX f(model.num_dofs());
  for (auto _ : bench) {
    compute_forces(model, s.x, s.v, f);
    benchmark::DoNotOptimize(f.data());
  }
  bench.counters["springs"] = model.springs.size();
  bench.counters["springs_per_s"] = benchmark::Counter(
      static_cast<double>(model.springs.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ComputeForces)->Arg(10)->Arg(20)->Unit(benchmark::kMicrosecond);

// The same through SpringBands (the loop the Simulator uses).
void BM_ComputeForcesBanded(benchmark::State& bench) {
  CubeSpec spec;
  spec.n = static_cast<int>(bench.range(0));
  const Model model = build_cube(spec);
  const SpringBands bands(model);
  if (!bands.dense()) bench.SkipWithError("the cube's springs do not fill their bands");
  State s = rest_state(model);
  for (int i = 0; i < s.x.size(); ++i) s.x[i] += 1e-3 * std::sin(0.37 * i);
  VecX f(model.num_dofs());
  for (auto _ : bench) {
    bands.compute_forces(model, s.x, s.v, f);
    benchmark::DoNotOptimize(f.data());
  }
  bench.counters["springs"] = model.springs.size();
  bench.counters["springs_per_s"] = benchmark::Counter(
      static_cast<double>(model.springs.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ComputeForcesBanded)->Arg(10)->Arg(20)->Unit(benchmark::kMicrosecond);

// One step (integrator + contact) of the seed scene: cube n = 10 on the 20-degree slope,
// after 0.5 s of settling so that contacts are active.
void BM_SeedSlopeStep(benchmark::State& bench, const std::string& integrator) {
  const Model model = build_cube(CubeSpec{});
  SimulatorOptions options;
  options.dt = 0.001;
  options.output_interval = 1.0;
  Simulator sim(model, rest_state(model), make_integrator(integrator), options);
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
  sim.run_until(0.5);
  for (auto _ : bench) {
    if (!sim.step().ok) bench.SkipWithError("step failed");
  }
  bench.counters["contacts"] = sim.contacts().contact_count();
}

}  // namespace

int main(int argc, char** argv) {
  for (const std::string& name : jelly::integrator_names()) {
    benchmark::RegisterBenchmark(("BM_SeedSlopeStep/" + name).c_str(), BM_SeedSlopeStep, name)
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
