#!/usr/bin/python3
"""Figures of the Python module jelly (docs/python.md): what calling C++ from Python costs.

1. step: sim.step() called from Python on the seed cube (n = 10 on the 20-degree slope, rk4,
   dt = 1 ms, after 0.5 s of settling: the set-up of jelly_core_benchmark's
   BM_SeedSlopeStep/rk4) against the same steps taken by the C++ loop of run_until, in the same
   process, interleaved, best and median of the repeats; and the bare per-call overhead on a
   2 x 2 x 2 cube, where a step costs almost nothing.
2. view: reading the positions of a 64,000-particle jelly (n = 40): the view's address is the
   C++ buffer's, and reading costs the same whatever the size, against copying them.
3. sweep: the same 8 runs on a 2-worker LocalCluster and in a serial loop.
4. threads: 2 simulators (seed cube, rk4, 1 thread each) run in 2 Python threads against the
   same two runs one after the other, best and median of the repeats (the GIL is released while
   C++ steps, and each simulator has its own lock).
5. rollout: 64 launches of a 5 x 5 x 5 cube onto the slope (random initial velocities), 500 steps
   each (rk4, dt 1 ms), positions kept at every step: jelly.rollout (on all cores, and on one
   thread) against a Python loop of sim.step() copying sim.state.x into the same array,
   alternating, with the CPU time (user + system) each took; the arrays are checked equal.

    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_python.py \
        [--out docs/bench] [step|view|sweep|threads|rollout ...]

With --out DIR each benchmark but sweep also writes its table, DIR/python_<name>/table.csv, with
the date, machine and load (scripts/bench_csv.py); scripts/bench_page.py renders it into
docs/python.md.
"""

import os
import pathlib
import statistics
import sys
import time

import numpy as np

import jelly

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_csv import MeasuredTable  # noqa: E402

SCENES = pathlib.Path(__file__).resolve().parents[1] / "scenes"
OUT = None  # --out: the folder of the tables' CSV files


def table(name, description):
    return MeasuredTable(name, description, getattr(jelly, "__version__", None))


def us(seconds):
    return f"{seconds * 1e6:.2f} us"


def save(measured, header, rows):
    if OUT:
        print("  wrote " + measured.write(OUT, header, rows))


def seed_simulator(n=10):
    spec = jelly.CubeSpec()
    spec.n = n
    model = jelly.build_cube(spec)
    options = jelly.SimulatorOptions()
    options.dt = 0.001
    options.output_interval = 1.0
    sim = jelly.Simulator(model, integrator="rk4", options=options)
    sim.add_terrain(jelly.Plane.slope(20))
    sim.run_until(0.5)
    return sim


def per_step_python(sim, steps):
    step = sim.step
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return (time.perf_counter() - start) / steps


def per_step_cpp(sim, steps):
    start = time.perf_counter()
    sim.run_until(sim.t + steps * sim.options.dt - 1e-9)
    return (time.perf_counter() - start) / steps


def bench_step(repeats=15, steps=400):
    measured = table("python_step", f"sim.step() from Python against the C++ loop of run_until,"
                     f" interleaved in one process, {repeats} repeats; rk4, dt 1 ms")
    rows = []
    for label, n, count in (("seed cube n = 10 (1000 particles, 12,876 springs)", 10, steps),
                            ("2 x 2 x 2 cube (call overhead)", 2, 20000)):
        sim = seed_simulator(n)
        py, cpp = [], []
        for _ in range(repeats):  # interleaved, so that load changes hit both alike
            py.append(per_step_python(sim, count))
            cpp.append(per_step_cpp(sim, count))
        print(f"step, {label}, {repeats} x {count} steps:")
        print(f"  sim.step() from Python: best {min(py) * 1e6:8.2f} us, median "
              f"{statistics.median(py) * 1e6:8.2f} us")
        print(f"  C++ loop (run_until):   best {min(cpp) * 1e6:8.2f} us, median "
              f"{statistics.median(cpp) * 1e6:8.2f} us")
        print(f"  Python / C++: best {min(py) / min(cpp):.3f}, median "
              f"{statistics.median(py) / statistics.median(cpp):.3f}, difference of the bests "
              f"{(min(py) - min(cpp)) * 1e6:+.2f} us per step")
        short = "seed cube" if n == 10 else "2 x 2 x 2 cube"
        rows += [[f"{short}, `sim.step()` from Python", us(min(py)), us(statistics.median(py))],
                 [f"{short}, C++ loop (`run_until`)", us(min(cpp)), us(statistics.median(cpp))],
                 [f"{short}, Python / C++", f"{min(py) / min(cpp):.2f}",
                  f"{statistics.median(py) / statistics.median(cpp):.2f}"]]
    save(measured, ["case", "best per step", "median per step"], rows)


def bench_view():
    measured = table("python_view", "reading the positions of a 64,000-particle cube (n = 40)"
                     " and of an 8-particle one: best of 7 x 200 reads")
    rows = []
    scene = jelly.load_scene(SCENES / "seed_slope.json", {"cube.n": 40})
    sim = jelly.Simulator(scene)
    x = sim.state.x
    print(f"view, n = 40: {sim.model.num_particles} particles, positions {x.nbytes / 1e6:.3f} MB")
    address = sim.state.x.__array_interface__["data"][0]
    print(f"  sim.state.x: shape {x.shape}, owndata {x.flags.owndata}, writeable "
          f"{x.flags.writeable}, same buffer on every read: "
          f"{all(sim.state.x.__array_interface__['data'][0] == address for _ in range(10))}, "
          f"np.shares_memory(sim.state.x, sim.state.x): "
          f"{np.shares_memory(sim.state.x, sim.state.x)}")
    sim.step()
    print(f"  a view read before a step shows the state after it: "
          f"{np.array_equal(x, sim.state.x)}")
    for label, read in (("read sim.state.x (view)", lambda: sim.state.x),
                        ("x.sum() on the view", lambda: sim.state.x.sum()),
                        ("np.array(sim.state.x) (a copy)", lambda: np.array(sim.state.x))):
        times = []
        for _ in range(7):
            start = time.perf_counter()
            for _ in range(200):
                read()
            times.append((time.perf_counter() - start) / 200)
        print(f"  {label:32s} best {min(times) * 1e6:9.2f} us")
        rows.append([f"{label}, 64,000 particles", us(min(times))])
    small = jelly.Simulator(jelly.load_scene(SCENES / "seed_slope.json", {"cube.n": 2}))
    times = []
    for _ in range(7):
        start = time.perf_counter()
        for _ in range(2000):
            small.state.x
        times.append((time.perf_counter() - start) / 2000)
    print(f"  {'read sim.state.x, 8 particles':32s} best {min(times) * 1e6:9.2f} us")
    rows.append(["read sim.state.x (view), 8 particles", us(min(times))])
    save(measured, ["read", "best"], rows)


def bench_sweep(workers=2):
    from distributed import Client, LocalCluster
    scene = jelly.load_scene(SCENES / "seed_slope.json", {"duration": 1.5})
    parameters = {"springs.structural.ks": [1000, 1400, 2000, 2800],
                  "integrator.name": ["rk4", "midpoint"]}
    points = jelly.sweep_points(parameters)
    start = time.perf_counter()
    for point in points:
        sim = jelly.Simulator(scene.with_overrides(point))
        sim.run_until(scene.duration)
    serial = time.perf_counter() - start
    start = time.perf_counter()
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        started = time.perf_counter()
        table = jelly.sweep(scene, parameters, client=client, out_dir=None)
        swept = time.perf_counter() - started
    total = time.perf_counter() - start
    print(f"sweep, {len(points)} runs of the seed slope ({scene.duration} s each, no files), "
          f"{os.cpu_count()} cores:")
    print(f"  serial loop: {serial:.2f} s")
    print(f"  jelly.sweep on {workers} workers: {swept:.2f} s (with starting and stopping the "
          f"cluster: {total:.2f} s); speed-up {serial / swept:.2f}")
    print(f"  statuses: {sorted(set(table['status']))}, worker time summed "
          f"{table['wall_seconds'].sum():.2f} s")


def bench_threads(repeats=7, seconds=1.0):
    import threading

    def fresh():
        sim = seed_simulator(10)
        sim.set_threads(1)  # one core each: the threads are the parallelism measured
        return sim

    def run(sim):
        sim.run_until(sim.t + seconds)

    measured = table("python_threads", f"2 seed cubes x {seconds:g} s (rk4, dt 1 ms, 1 solver"
                     f" thread each), {repeats} repeats: one after the other against 2 Python"
                     " threads")
    serial, threaded = [], []
    for _ in range(repeats):
        a, b = fresh(), fresh()
        start = time.perf_counter()
        run(a)
        run(b)
        serial.append(time.perf_counter() - start)
        a, b = fresh(), fresh()
        threads = [threading.Thread(target=run, args=(s,)) for s in (a, b)]
        start = time.perf_counter()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        threaded.append(time.perf_counter() - start)
    print(f"2 seed cubes x {seconds:g} s (rk4, dt 1 ms, 1 thread each), {repeats} repeats, "
          f"load average {os.getloadavg()[0]:.2f}")
    print(f"  one after the other: best {min(serial):.3f} s, median {statistics.median(serial):.3f} s")
    print(f"  2 Python threads:    best {min(threaded):.3f} s, "
          f"median {statistics.median(threaded):.3f} s")
    print(f"  speed-up: best {min(serial) / min(threaded):.2f}, median "
          f"{statistics.median(serial) / statistics.median(threaded):.2f}")
    save(measured, ["", "best", "median"],
         [["one after the other", f"{min(serial):.3f} s", f"{statistics.median(serial):.3f} s"],
          ["2 Python threads", f"{min(threaded):.3f} s", f"{statistics.median(threaded):.3f} s"],
          ["speed-up", f"{min(serial) / min(threaded):.2f}",
           f"{statistics.median(serial) / statistics.median(threaded):.2f}"]])


def bench_rollout(repeats=3, runs=64, steps=500):
    scene = jelly.load_scene(SCENES / "seed_slope.json", {"cube.n": 5})
    rng = np.random.default_rng(38)
    launches = [{"bodies[0].velocity": [float(rng.uniform(-2, 2)), float(rng.uniform(0, 3)),
                                        float(rng.uniform(-2, 2))]} for _ in range(runs)]
    duration = steps * scene.integrator.dt

    def timed(f):
        cpu, start = os.times(), time.perf_counter()
        out = f()
        wall, after = time.perf_counter() - start, os.times()
        return out, wall, (after.user - cpu.user) + (after.system - cpu.system)

    def python_loop():
        positions = np.empty((runs, steps + 1, 125, 3))
        for k, launch in enumerate(launches):
            sim = jelly.Simulator(scene.with_overrides(launch))
            positions[k, 0] = sim.state.x
            for i in range(steps):
                sim.step()
                positions[k, i + 1] = sim.state.x
        return positions

    cases = {
        "jelly.rollout, all cores": lambda: jelly.rollout(scene, launches, duration, every=0),
        "jelly.rollout, threads=1": lambda: jelly.rollout(scene, launches, duration, every=0,
                                                          threads=1),
        "Python loop of step()": python_loop,
    }
    measured = table("python_rollout", f"{runs} launches of a 5 x 5 x 5 cube onto the slope,"
                     f" {steps} steps each (rk4, dt 1 ms), positions at every step; the cases"
                     f" alternate, {repeats} repeats, best wall time with the CPU time of the"
                     " same repeat; the arrays equal bit for bit")
    times = {name: [] for name in cases}
    loads = []
    for _ in range(repeats):  # alternating, so that load changes hit every case alike
        loads.append(os.getloadavg()[0])
        results = {}
        for name, f in cases.items():
            out, wall, cpu = timed(f)
            times[name].append((wall, cpu))
            results[name] = out if isinstance(out, np.ndarray) else out.positions
        first = results["jelly.rollout, all cores"]
        assert all(r.tobytes() == first.tobytes() for r in results.values())
    print(f"rollout: {runs} launches of a 5 x 5 x 5 cube, {steps} steps each (rk4, dt 1 ms), "
          f"positions at every step, {repeats} repeats, {os.cpu_count()} cores, load average "
          f"{min(loads):.2f}-{max(loads):.2f}; the arrays equal bit for bit")
    loop = min(w for w, _ in times["Python loop of step()"])
    labels = {"jelly.rollout, all cores": f"`jelly.rollout`, all cores ({os.cpu_count()})",
              "jelly.rollout, threads=1": "`jelly.rollout`, `threads=1`",
              "Python loop of step()": "Python loop of `sim.step()`"}
    rows = []
    for name, values in times.items():
        best = min(values)
        rows.append([labels[name], f"{best[0]:.3f} s", f"{best[1]:.3f} s",
                     f"{best[1] / best[0]:.2f}", f"{loop / best[0]:.2f}"])
    save(measured, ["case", "wall (best)", "CPU", "cores used", "loop / case"], rows)
    for name, values in times.items():
        best = min(values)
        print(f"  {name:26s} best {best[0]:6.3f} s wall, {best[1]:6.3f} s CPU "
              f"({best[1] / best[0]:.2f} cores), median "
              f"{statistics.median(w for w, _ in values):6.3f} s; Python loop / this: "
              f"{loop / best[0]:.2f}")


if __name__ == "__main__":
    arguments = sys.argv[1:]
    if arguments[:1] == ["--out"] and len(arguments) >= 2:
        OUT, arguments = arguments[1], arguments[2:]
    chosen = arguments or ["step", "view", "sweep", "threads", "rollout"]
    for name in chosen:
        {"step": bench_step, "view": bench_view, "sweep": bench_sweep,
         "threads": bench_threads, "rollout": bench_rollout}[name]()
