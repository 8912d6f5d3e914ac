// Micro-benchmarks of the hot loop: the seed cube's force evaluation and one step of each
// integrator on the seed slope (contact included).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/jelly.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/terrain/plane.hpp>

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

// The same through SpringBands (the loop the Simulator uses), on range(1) threads.
void BM_ComputeForcesBanded(benchmark::State& bench) {
  CubeSpec spec;
  spec.n = static_cast<int>(bench.range(0));
  const int threads = static_cast<int>(bench.range(1));
  const Model model = build_cube(spec);
  const SpringBands bands(model);
  if (!bands.dense()) bench.SkipWithError("the cube's springs do not fill their bands");
  State s = rest_state(model);
  for (int i = 0; i < s.x.size(); ++i) s.x[i] += 1e-3 * std::sin(0.37 * i);
  VecX f(model.num_dofs());
  for (auto _ : bench) {
    bands.compute_forces(model, s.x, s.v, f, threads);
    benchmark::DoNotOptimize(f.data());
  }
  bench.counters["springs"] = model.springs.size();
  bench.counters["springs_per_s"] = benchmark::Counter(
      static_cast<double>(model.springs.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ComputeForcesBanded)
    ->ArgsProduct({{10, 20, 40}, {1, 2}})
    ->Unit(benchmark::kMicrosecond);

// What two threads can gain on this machine, apart from jelly's code (docs/threads.md,
// "Measurements"): two passes over the 3 n^3 entries of the n^3 cube's vectors on
// range(1) threads, split as the particle loops are (parallel::for_ranges). BM_StreamingPass is
// rk4's update between two stages (7 vectors: the step's x and v, the stage's acceleration,
// position and velocity, the two sums of slopes): little arithmetic per byte, so memory and cache
// traffic decide. BM_ComputePass does a spring's square root and division per entry on values
// kept in registers: arithmetic decides. Wall times (a thread the host does not run counts).
void BM_StreamingPass(benchmark::State& bench) {
  const long n = 3 * bench.range(0) * bench.range(0) * bench.range(0);
  const int threads = static_cast<int>(bench.range(1));
  std::vector<VecX> w(7, VecX::Constant(n, 1.0));
  for (auto _ : bench) {
    parallel::for_ranges(
        threads, n,
        [&](long begin, long end) {
          const Real* __restrict x = w[0].data();
          const Real* __restrict v = w[1].data();
          const Real* __restrict a = w[2].data();
          Real* __restrict xs = w[3].data();
          Real* __restrict vs = w[4].data();
          Real* __restrict dx = w[5].data();
          Real* __restrict dv = w[6].data();
          for (long i = begin; i < end; ++i) {
            dx[i] += 2 * vs[i];
            dv[i] += 2 * a[i];
            xs[i] = x[i] + 1e-3 * vs[i];
            vs[i] = v[i] + 1e-3 * a[i];
          }
        },
        parallel::kMinItemsPerThread, 3);
    benchmark::DoNotOptimize(w[6].data());
    benchmark::ClobberMemory();
  }
  bench.counters["bytes_per_s"] = benchmark::Counter(static_cast<double>(n) * 10 * sizeof(Real),
                                                     benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_StreamingPass)
    ->ArgsProduct({{20, 40}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

void BM_ComputePass(benchmark::State& bench) {
  const long n = 3 * bench.range(0) * bench.range(0) * bench.range(0);
  const int threads = static_cast<int>(bench.range(1));
  std::vector<Real> out(static_cast<size_t>(n / 1024 + 1), 0.0);
  for (auto _ : bench) {
    parallel::for_ranges(threads, n, [&](long begin, long end) {
      Real sum = 0;
      for (long i = begin; i < end; ++i) {
        const Real d = 1.0 + 1e-9 * static_cast<Real>(i & 255);
        const Real length = std::sqrt(d * d + 2.0);
        sum += (length - 1.0) / (length + 1e-300);
      }
      out[static_cast<size_t>(begin / 1024)] = sum;
    });
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ComputePass)
    ->ArgsProduct({{20, 40}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

// implicit_euler's matrix-free backward-Euler matrix (core/detail/band_system.hpp) of the n^3
// seed cube, slightly deformed, at dt = 1/60 s, assembled on `threads` threads. `error` says
// why it could not be built (then the benchmark is skipped).
struct DeformedCubeSystem {
  Model model;
  SpringBands bands;
  BandSystem system;  // points to bands: not copyable, not movable
  State state;        // the deformed cube, at rest
  VecX kw;            // K v of the last assembly
  const char* error = nullptr;

  // whole_rows: assemble and multiply each thread's rows as one block (every band over the
  // whole range, as before 2026-11-29) instead of the default blocks of rows (the same bits).
  DeformedCubeSystem(int n, int threads, bool single_precision = false, bool whole_rows = false)
      : model(build_cube([n] {
          CubeSpec spec;
          spec.n = n;
          return spec;
        }())),
        bands(model),
        system(bands, model.num_particles(), single_precision) {
    if (!bands.dense()) {
      error = "the cube's springs do not fill their bands";
      return;
    }
    if (whole_rows) system.set_row_block(model.num_particles());
    state = rest_state(model);
    for (int i = 0; i < state.x.size(); ++i) state.x[i] += 1e-3 * std::sin(0.37 * i);
    kw.resize(model.num_dofs());
    if (!assemble(threads)) error = "a spring collapsed";
  }
  DeformedCubeSystem(const DeformedCubeSystem&) = delete;
  DeformedCubeSystem& operator=(const DeformedCubeSystem&) = delete;

  // Assembles A = M - h D - h^2 K at `state` (h = 1/60 s) and K v; false when a spring
  // collapsed.
  bool assemble(int threads) {
    const Real h = 1.0 / 60;
    return system.assemble(model, state.x, state.v, DefinitenessFix::kClampCompressed, h, h * h,
                           state.v, kw, threads);
  }

  // The counters of a pass over the springs: their number and the time per spring.
  void count_springs(benchmark::State& bench) const {
    const double springs = static_cast<double>(model.springs.size());
    bench.counters["springs"] = springs;
    bench.counters["s_per_spring"] = benchmark::Counter(
        springs, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  }

  // False (and the benchmark skipped, saying why) when the system could not be built.
  bool usable(benchmark::State& bench) const {
    if (error != nullptr) bench.SkipWithError(error);
    return error == nullptr;
  }

  // A smooth vector of the system's size.
  VecX vector() const {
    VecX p(model.num_dofs());
    for (int i = 0; i < p.size(); ++i) p[i] = std::cos(0.11 * i);
    return p;
  }
};

// One product y = A p (the inner loop of implicit_euler's CG); arguments n, the threads,
// whether the coefficients are in single precision (1; implicit_euler's at cg_tolerance >= 1e-6)
// and whether each thread's rows are one block (1: the loop order before 2026-11-29).
void BM_MatrixFreeProduct(benchmark::State& bench) {
  const int threads = static_cast<int>(bench.range(1));
  const DeformedCubeSystem cube(static_cast<int>(bench.range(0)), threads, bench.range(2) != 0,
                                bench.range(3) != 0);
  if (!cube.usable(bench)) return;
  const VecX p = cube.vector();
  VecX y(p.size());
  for (auto _ : bench) {
    cube.system.multiply(p, y, threads);
    benchmark::DoNotOptimize(y.data());
  }
  cube.count_springs(bench);
}
BENCHMARK(BM_MatrixFreeProduct)
    ->ArgsProduct({{20, 40}, {1, 2}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One assembly of the matrix-free system (implicit_euler's per-step A = M - h D - h^2 K and
// K v, core/detail/band_system.hpp) on the deformed cube; arguments n, the threads and whether
// each thread's rows are one block (as BM_MatrixFreeProduct).
void BM_MatrixFreeAssembly(benchmark::State& bench) {
  const int threads = static_cast<int>(bench.range(1));
  DeformedCubeSystem cube(static_cast<int>(bench.range(0)), threads, false, bench.range(2) != 0);
  if (!cube.usable(bench)) return;
  cube.state.v = 0.1 * cube.vector();  // moving: the dampers' terms too
  for (auto _ : bench) {
    if (!cube.assemble(threads)) {
      bench.SkipWithError("a spring collapsed");
      break;
    }
    benchmark::DoNotOptimize(cube.kw.data());
  }
  cube.count_springs(bench);
}
BENCHMARK(BM_MatrixFreeAssembly)
    ->ArgsProduct({{20, 40}, {1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A solve of 100 iterations of implicit_euler's matrix-free block-Jacobi CG
// (solvers/linear/detail/cg_solver.hpp) on the same system from x = 0: 101 products (the starting
// residual's and one per iteration) plus CG's vector operations, ordered sums and
// preconditioner; s_per_cg_iteration is the solve's time / 100. Arguments n, the threads, single
// precision and whole rows (as BM_MatrixFreeProduct).
void BM_MatrixFreeCgIterations(benchmark::State& bench) {
  const int threads = static_cast<int>(bench.range(1));
  const DeformedCubeSystem cube(static_cast<int>(bench.range(0)), threads, bench.range(2) != 0,
                                bench.range(3) != 0);
  if (!cube.usable(bench)) return;
  MatrixFreeCg cg;
  const LinearResult blocks = cg.set_diagonal_blocks(
      cube.model.num_particles(), [&](int i, Real d[9]) { cube.system.diagonal_block(i, d); },
      threads);
  if (!blocks.ok()) {
    bench.SkipWithError(blocks.message.c_str());
    return;
  }
  const VecX b = cube.vector();
  VecX x(b.size());
  const MatrixFreeCg::Product apply = [&](const VecX& in, VecX& out) {
    cube.system.multiply(in, out, threads);
  };
  constexpr int kIterations = 100;
  for (auto _ : bench) {
    x.setZero();
    const LinearResult r = cg.solve(apply, b, x, 1e-300, kIterations, threads);
    benchmark::DoNotOptimize(x.data());
    if (r.iterations != kIterations) {
      bench.SkipWithError("CG stopped early");
      break;
    }
  }
  bench.counters["s_per_cg_iteration"] = benchmark::Counter(
      kIterations, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MatrixFreeCgIterations)
    ->ArgsProduct({{20, 40}, {1, 2}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

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
