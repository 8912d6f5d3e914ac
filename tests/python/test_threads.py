"""One simulator used from several Python threads: calls are serialised by a lock per simulator
(no crash, no lost step); Ctrl-C stops run_until; run_until applies jelly run's limits."""

import os
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import jelly


def implicit_cube(n=4):
    spec = jelly.CubeSpec()
    spec.n = n
    options = jelly.SimulatorOptions()
    options.dt = 1e-3
    sim = jelly.Simulator(jelly.build_cube(spec), integrator="implicit_euler", options=options)
    sim.add_terrain(jelly.Plane.slope(20))
    return sim


def run_in_threads(*targets):
    errors = []

    def guarded(target):
        try:
            target()
        except BaseException as e:  # noqa: BLE001  (reported below)
            errors.append(e)

    threads = [threading.Thread(target=guarded, args=(t,)) for t in targets]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []


def test_two_threads_stepping_one_simulator_lose_no_step():
    sim = implicit_cube()
    alone = implicit_cube()

    def step_300():
        for _ in range(300):
            assert sim.step().ok

    run_in_threads(step_300, step_300)
    assert sim.total_steps == 600
    assert sim.integrator.steps == 600
    # 600 steps one after the other: the same state bit for bit as one thread taking them.
    for _ in range(600):
        alone.step()
    assert sim.t == alone.t
    assert np.array_equal(sim.state.x, alone.state.x)


@pytest.mark.parametrize("contact", ["seed", "coulomb"])
def test_add_terrain_and_reads_during_another_thread_s_run_until(scenes, contact):
    # Before the lock, planes added during a run crashed it now and then (seed contact).
    for _ in range(6):
        sim = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 6}))
        started = threading.Event()
        reads = []

        def run():
            sim.run_until(0.5, callback=lambda s: started.set())

        def meddle():
            started.wait()
            params = jelly.ContactParams()
            params.model = contact
            for k in range(300):
                sim.add_terrain(jelly.Plane.slope(20 + 0.01 * k, [0, 0.001 * k, 0], params))
                if k % 30 == 0:
                    reads.append((sim.t, sim.total_steps, float(sim.state.x[0, 1]),
                                  sim.kinetic_energy(), sim.snapshot().total_steps, repr(sim)))

        run_in_threads(run, meddle)
        assert sim.report.status == "completed" and sim.report.steps == 500
        assert len(sim.terrains) == 301
        assert len(reads) == 10
        # Each read saw a whole step: its time and step count agree.
        for t, steps, *_ in reads:
            assert t == pytest.approx(steps * 1e-3, abs=1e-9)


def test_snapshot_restore_and_set_threads_from_threads():
    sim = implicit_cube(3)
    snapshot = sim.snapshot()

    def restore_and_run():
        for _ in range(5):
            sim.restore(snapshot)
            sim.run_until(0.02)

    def set_threads():
        for k in range(50):
            sim.set_threads(1 + k % 2)
            assert sim.options.threads in (1, 2)

    run_in_threads(restore_and_run, set_threads, restore_and_run)
    assert sim.t == pytest.approx(0.02)


def test_a_callback_may_call_the_simulator_it_runs_in():
    sim = implicit_cube(2)
    seen = []
    sim.run_until(0.005, callback=lambda s: seen.append((s.t, s.total_steps, s.state.x.shape)))
    assert len(seen) == 6


def test_run_until_applies_the_limits_of_jelly_run():
    sim = implicit_cube(2)
    with pytest.raises(jelly.InputError, match=r"t_end = 1e\+09 is invalid: .*at most 1000000000 steps"):
        sim.run_until(1e9)  # 10^12 steps
    state = sim.state.copy()
    state.t = -1e12
    sim.state = state
    with pytest.raises(jelly.InputError, match=r"state\.t = -1e\+12 is invalid"):
        sim.run_until(1.0)
    assert sim.total_steps == 0


def test_cube_counts_refuse_an_edge_out_of_range():
    with pytest.raises(jelly.InputError, match=r"n = 2000000 is invalid"):
        jelly.cube_spring_count(2000000)
    with pytest.raises(ValueError, match=r"n = -5 is invalid"):
        jelly.cube_particle_count(-5)
    assert jelly.cube_spring_count(10) == 12876


INTERRUPTED_RUN = textwrap.dedent("""
    import os, signal, threading
    import jelly
    spec = jelly.CubeSpec()
    spec.n = 2
    spec.gravity = [0, 0, 0]  # at rest for ever: never diverges
    sim = jelly.Simulator(jelly.build_cube(spec), integrator="rk4")
    threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    try:
        print("not interrupted:", sim.run_until(1e5))  # 10^8 steps: minutes
    except KeyboardInterrupt:
        t = sim.t
        assert 0 < t < 1e5, t
        report = sim.run_until(t + 0.01)  # still usable
        assert report.status == "completed" and report.steps == 10, report
        print("interrupted at", t)
""")


def test_ctrl_c_stops_run_until_and_leaves_the_simulator_usable():
    result = subprocess.run([sys.executable, "-c", INTERRUPTED_RUN], capture_output=True,
                            text=True, timeout=120, env=os.environ.copy())
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("interrupted at"), result.stdout


def test_a_wrong_simulator_argument_is_a_type_error(tmp_path):
    with pytest.raises(TypeError, match="expected a jelly.Simulator, not str"):
        jelly.H5Recorder(str(tmp_path / "r.h5"), "sim")
    with pytest.raises(TypeError, match="expected a jelly.Simulator, not int"):
        jelly.Simulator.step(3)


def test_two_simulators_run_at_the_same_time_in_two_threads():
    # Each run waits, inside its first frame, until the other has started: this ends only if
    # the two run_until calls are in progress at the same time (a lock per simulator, not one
    # for all, and the GIL released while stepping).
    sims = [implicit_cube(3), implicit_cube(3)]
    started = [threading.Event(), threading.Event()]
    met = []

    def run(i):
        def first_frame(sim):
            if not started[i].is_set():
                started[i].set()
                met.append(started[1 - i].wait(timeout=60))
        sims[i].run_until(0.05, callback=first_frame)

    run_in_threads(lambda: run(0), lambda: run(1))
    assert met == [True, True]
    assert [s.total_steps for s in sims] == [50, 50]
