// The implicit Euler's pieces on the seed cube: assembly, every linear-solver backend on the same
// matrices, and one whole implicit step per backend. Run on one core:
//   OPENBLAS_NUM_THREADS=1 taskset -c 0 build/bench/jelly_implicit_benchmark
// Benchmark arguments: n (particles per edge), ks (N/m, all spring types; kd = 50), and a
// third argument that selects an ordering, a tolerance or a backend.
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>

#include <chrono>
#include <map>
#include <memory>
#include <random>
#include <tuple>

#include <jelly/core/detail/forces.hpp>
#include <jelly/core/detail/jacobian.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/solvers/linear/detail/cg_solver.hpp>
#include <jelly/solvers/linear/detail/cholmod_solver.hpp>
#include <jelly/solvers/linear/detail/ldlt_solver.hpp>
#include <jelly/solvers/simulator.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly {
namespace {

constexpr Real kDt = 1.0 / 60;

CubeSpec cube(int n, Real ks) {
  CubeSpec spec;
  spec.n = n;
  for (auto& c : spec.springs) c = SpringCoefficients{ks, 50};
  return spec;
}

// A deformed, moving state of the cube: every particle displaced by up to 5% of the spacing,
// velocities up to 0.5 m/s (seeded, so every backend sees the same matrices).
State deformed(const Model& model, int seed, Real amplitude) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  State s = rest_state(model);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) {
    s.x[i] += amplitude * u(rng);
    s.v[i] = 0.5 * u(rng);
  }
  return s;
}

// The backward-Euler system A = M - h D - h^2 K, b = h (f + h K v) at a deformed state, and the
// same at a nearby later state (for the lagged preconditioner).
struct Problem {
  Model model;
  std::unique_ptr<SpringJacobian> jacobian;
  SparseMatrix a0, a1;
  VecX b0, b1;
};

void system_at(const Problem& p, const State& s, SparseMatrix& a, VecX& b) {
  VecX f(p.model.num_dofs()), kv(p.model.num_dofs());
  compute_forces(p.model, s.x, s.v, f);
  p.jacobian->assemble_system(p.model, s.x, s.v, JacobianOptions{}, kDt, kDt * kDt, a, s.v, kv);
  b = kDt * (f + kDt * kv);
}

const Problem& problem(int n, Real ks) {
  static std::map<std::pair<int, Real>, std::unique_ptr<Problem>> cache;
  auto& slot = cache[{n, ks}];
  if (!slot) {
    slot = std::make_unique<Problem>();
    Problem& p = *slot;
    p.model = build_cube(cube(n, ks));
    p.jacobian = std::make_unique<SpringJacobian>(p.model);
    p.a0 = p.jacobian->make_matrix();
    p.a1 = p.jacobian->make_matrix();
    const Real spacing = 4.0 / (n - 1);
    State s0 = deformed(p.model, 1, 0.05 * spacing);
    system_at(p, s0, p.a0, p.b0);
    // A later state: moved on by 5 steps of the velocities, plus a little more deformation.
    State s1 = s0;
    const State noise = deformed(p.model, 2, 0.01 * spacing);
    s1.x += 5 * kDt * s0.v + (noise.x - rest_state(p.model).x);
    system_at(p, s1, p.a1, p.b1);
  }
  return *slot;
}

Real ks_of(const benchmark::State& st) { return static_cast<Real>(st.range(1)); }

void set_size_counters(benchmark::State& st, const Problem& p) {
  st.counters["unknowns"] = static_cast<double>(p.a0.rows());
  st.counters["nnz"] = static_cast<double>(p.a0.nonZeros());
}

void BM_Assemble(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  SparseMatrix a = p.jacobian->make_matrix();
  const State s = deformed(p.model, 1, 0.02);
  VecX kv(p.model.num_dofs()), f(p.model.num_dofs());
  for (auto _ : st) {
    compute_forces(p.model, s.x, s.v, f);
    p.jacobian->assemble_system(p.model, s.x, s.v, JacobianOptions{}, kDt, kDt * kDt, a, s.v, kv);
    benchmark::DoNotOptimize(a.valuePtr());
  }
  set_size_counters(st, p);
}

CholmodOrdering ordering_arg(int64_t k) { return static_cast<CholmodOrdering>(k); }

void BM_CholmodAnalyze(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  CholmodOptions o;
  o.ordering = ordering_arg(st.range(2));
  for (auto _ : st) {
    CholmodSolver solver(o);
    if (!solver.analyze(p.a0).ok()) st.SkipWithError("analyze failed");
  }
  st.SetLabel(std::string(cholmod_ordering_name(o.ordering)));
  set_size_counters(st, p);
}

void BM_CholmodFactorize(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  CholmodOptions o;
  o.ordering = ordering_arg(st.range(2));
  CholmodSolver solver(o);
  solver.analyze(p.a0);
  for (auto _ : st) {
    if (!solver.factorize(p.a0).ok()) st.SkipWithError("factorize failed");
  }
  st.SetLabel(std::string(cholmod_ordering_name(o.ordering)));
  st.counters["nnz_L"] = solver.factor_non_zeros();
  st.counters["GFlop"] = solver.factor_flops() / 1e9;
  set_size_counters(st, p);
}

void BM_CholmodSolve(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  CholmodOptions o;
  o.ordering = ordering_arg(st.range(2));
  CholmodSolver solver(o);
  solver.analyze(p.a0);
  solver.factorize(p.a0);
  VecX x = VecX::Zero(p.b0.size());
  for (auto _ : st) solver.solve(p.b0, x);
  st.SetLabel(std::string(cholmod_ordering_name(o.ordering)));
  set_size_counters(st, p);
}

void BM_LdltFactorize(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  LdltSolver solver;
  solver.analyze(p.a0);
  for (auto _ : st) {
    if (!solver.factorize(p.a0).ok()) st.SkipWithError("factorize failed");
  }
  set_size_counters(st, p);
}

void BM_LdltSolve(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  LdltSolver solver;
  solver.analyze(p.a0);
  solver.factorize(p.a0);
  VecX x = VecX::Zero(p.b0.size());
  for (auto _ : st) solver.solve(p.b0, x);
  set_size_counters(st, p);
}

// Times solver's solves of A1 x = b1 from x = 0 (the solver set up for A1).
void time_cg_solves(benchmark::State& st, CgSolver& solver, const Problem& p) {
  VecX x = VecX::Zero(p.b1.size());
  int iterations = 0;
  for (auto _ : st) {
    x.setZero();
    iterations = solver.solve(p.b1, x).iterations;
  }
  st.counters["cg_iterations"] = iterations;
  set_size_counters(st, p);
}

// CG from x = 0 to a relative residual of 1e-8 (range 2 = 0) or 1e-10 (1).
void BM_CgJacobiSolve(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  CgOptions o;
  o.tolerance = st.range(2) == 0 ? 1e-8 : 1e-10;
  CgSolver solver(o);
  solver.analyze(p.a1);
  solver.factorize(p.a1);
  time_cg_solves(st, solver, p);
}

// CG on A1 preconditioned by the CHOLMOD factor of A0 (a state 5 steps earlier).
void BM_CgLaggedSolve(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  CgOptions o;
  o.preconditioner = CgPreconditioner::kLaggedCholesky;
  o.tolerance = st.range(2) == 0 ? 1e-8 : 1e-10;
  o.refactor_iterations = 1000;
  o.lagged_iteration_limit = 1000;
  CgSolver solver(o);
  solver.analyze(p.a0);
  solver.factorize(p.a0);  // the lagged factor
  solver.factorize(p.a1);  // keeps it, multiplies by A1
  time_cg_solves(st, solver, p);
}

// Eigen's incomplete Cholesky (IC with AMD ordering, Eigen's default fill and shift) as the
// preconditioner of Eigen's CG, from x = 0 to a relative residual of 1e-8: the candidate that
// `auto` does not use (docs/implicit.md). Times the solve; the factorization, which a step would
// redo, is the counter ichol_ms.
void BM_IcholCgSolve(benchmark::State& st) {
  const Problem& p = problem(static_cast<int>(st.range(0)), ks_of(st));
  using Ichol = Eigen::IncompleteCholesky<Real, Eigen::Lower, Eigen::AMDOrdering<int>>;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Ichol> cg;
  cg.setTolerance(1e-8);
  cg.setMaxIterations(1000);
  const auto start = std::chrono::steady_clock::now();
  cg.compute(p.a1);
  st.counters["ichol_ms"] =
      1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (cg.info() != Eigen::Success) st.SkipWithError("incomplete Cholesky failed");
  VecX x;
  for (auto _ : st) {
    x = cg.solve(p.b1);
    benchmark::DoNotOptimize(x.data());
  }
  st.counters["cg_iterations"] = static_cast<double>(cg.iterations());
  set_size_counters(st, p);
}

// Whole implicit steps of the seed slope scene (cube at its seed pose above Plane::slope(20),
// coulomb contact), after warm-up steps; range 2 selects the backend.
const char* const kBackends[] = {"cholmod", "ldlt", "cg_jacobi", "cg_lagged_cholmod", "auto"};

void BM_ImplicitStep(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  const std::string backend = kBackends[st.range(2)];
  IntegratorOptions io;
  if (backend == "cg_jacobi" || backend == "cg_lagged_cholmod") {
    io.implicit.linear_solver = ImplicitLinearSolver::kCg;
    io.implicit.cg_preconditioner =
        backend == "cg_jacobi" ? CgPreconditionerKind::kJacobi : CgPreconditionerKind::kCholmod;
  } else {
    io.implicit.linear_solver = value_of(implicit_linear_solvers(), backend, "linear_solver");
  }
  const Model model = build_cube(cube(n, ks_of(st)));
  SimulatorOptions so;
  so.dt = kDt;
  Simulator sim(model, rest_state(model), make_integrator("implicit_euler", io), so);
  sim.add_terrain(std::make_unique<Plane>(Plane::slope(20)));
  // Warm up into the contact phase (n = 20 falls longer: it reaches the slope at t ~ 1.1 s).
  const int warm_up = n >= 20 ? 90 : 30;
  for (int i = 0; i < warm_up; ++i) sim.step();
  const Statistics before = sim.integrator().statistics();
  long steps = 0;
  for (auto _ : st) {
    if (!sim.step().ok) st.SkipWithError("step failed");
    ++steps;
  }
  const Statistics after = sim.integrator().statistics();
  const auto per_step = [&](const char* key) {
    return (after.at(key) - before.at(key)) / std::max<long>(steps, 1);
  };
  st.counters["factorizations/step"] = per_step("numeric_factorizations");
  st.counters["cg_its/step"] = per_step("cg_iterations");
  st.counters["assembly_ms/step"] = 1e3 * per_step("assembly_seconds");
  st.counters["factor_ms/step"] = 1e3 * per_step("factorization_seconds");
  st.counters["solve_ms/step"] = 1e3 * per_step("solve_seconds");
  st.SetLabel(
      backend + " -> " +
      std::string(static_cast<const ImplicitEuler&>(sim.integrator()).linear_solver_name()));
}

void orderings(benchmark::internal::Benchmark* b) {
  for (int ordering = 0; ordering < 4; ++ordering) {
    b->Args({10, 1400, ordering});
    b->Args({10, 100000, ordering});
  }
  b->Args({20, 1400, 0});
  b->Args({20, 1400, 1});
  b->Args({20, 1400, 2});
}
void sizes(benchmark::internal::Benchmark* b) {
  b->Args({10, 1400});
  b->Args({10, 100000});
  b->Args({20, 1400});
}
void tolerances(benchmark::internal::Benchmark* b) {
  for (int tol = 0; tol < 2; ++tol) {
    b->Args({10, 1400, tol});
    b->Args({10, 100000, tol});
    b->Args({20, 1400, tol});
  }
}

BENCHMARK(BM_Assemble)->Apply(sizes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CholmodAnalyze)->Apply(orderings)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CholmodFactorize)->Apply(orderings)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CholmodSolve)->Args({10, 1400, 1})->Args({20, 1400, 1})->Unit(benchmark::kMillisecond);
// LDLT at n = 20 is left out: one factorization takes minutes (docs/implicit.md).
void small_sizes(benchmark::internal::Benchmark* b) {
  b->Args({10, 1400});
  b->Args({10, 100000});
}
BENCHMARK(BM_LdltFactorize)->Apply(small_sizes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LdltSolve)->Apply(small_sizes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CgJacobiSolve)->Apply(tolerances)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CgLaggedSolve)->Apply(tolerances)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IcholCgSolve)->Apply(sizes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImplicitStep)
    ->ArgsProduct({{10}, {1400, 100000}, {0, 2, 3, 4}})
    ->Iterations(300)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImplicitStep)  // LDLT factorizes every step: 30 steps are enough
    ->ArgsProduct({{10}, {1400, 100000}, {1}})
    ->Iterations(30)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImplicitStep)
    ->ArgsProduct({{20}, {1400}, {0, 2, 3, 4}})
    ->Iterations(30)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace jelly

BENCHMARK_MAIN();
