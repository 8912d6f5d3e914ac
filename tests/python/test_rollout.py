"""Batched rollouts (jelly.rollout): each run's frames equal a Simulator of its scene run alone and
`jelly run`, bit for bit, for any thread count; a diverged run stops alone; runs of other
particle counts, bad overrides and overrides of the rollout's own fields are refused by name."""

import os
import pickle
import subprocess
import sys
import textwrap

import h5py
import numpy as np
import pytest

import jelly

# Launches of a 5 x 5 x 5 cube onto the slope, each with its own parameters: every kind of
# override the sweep takes (springs, masses, gravity, initial velocity, dt, integrator).
RUNS = [
    {},
    {"springs.structural.ks": 700, "springs.shear.kd": 20},
    {"bodies[0].velocity": [1.5, 2.0, -0.5]},
    {"gravity": [0, -3.0, 1.0], "cube.particle_mass": 0.5},
    {"integrator.dt": 0.0005},
    {"integrator.name": "implicit_euler", "integrator.dt": 0.002},
    {"integrator.name": "xpbd", "bodies[0].angular_velocity": [0, 3, 0]},
]


@pytest.fixture
def small_slope(scenes):
    return jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 5})


def alone(scene, overrides, duration, every, velocities=False):
    """The frames of one run by a Simulator of its own: positions (and velocities), times."""
    s = scene.with_overrides({**overrides, "duration": duration, "output_interval": every})
    sim = jelly.Simulator(s)
    xs, vs, ts = [], [], []

    def keep(sim):
        xs.append(np.array(sim.state.x))
        vs.append(np.array(sim.state.v))
        ts.append(sim.t)

    report = sim.run_until(duration, callback=keep)
    return np.array(xs), np.array(vs), np.array(ts), report


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_each_run_equals_its_simulator_alone_bit_for_bit(small_slope, threads):
    duration, every = 0.3, 0.02
    r = jelly.rollout(small_slope, RUNS, duration, every=every, velocities=True, threads=threads)
    assert r.positions.shape == (len(RUNS), 16, 125, 3)
    assert r.velocities.shape == r.positions.shape and r.times.shape == (len(RUNS), 16)
    assert list(r.status) == ["completed"] * len(RUNS), r.reasons
    assert r.ok.all() and (r.frames == 16).all()
    for k, overrides in enumerate(RUNS):
        x, v, t, report = alone(small_slope, overrides, duration, every)
        assert r.positions[k].tobytes() == x.tobytes(), k
        assert r.velocities[k].tobytes() == v.tobytes(), k
        assert r.times[k].tobytes() == t.tobytes(), k
        assert r.steps[k] == report.steps
    # The runs differ from each other (the overrides reached them).
    assert not np.array_equal(r.positions[0, -1], r.positions[1, -1])
    assert not np.array_equal(r.positions[0, -1], r.positions[2, -1])


def test_runs_equal_jelly_run_recordings(small_slope, run_cli, tmp_path):
    duration = 0.25
    r = jelly.rollout(small_slope, RUNS[:3], duration)  # every: the scene's 1/60 s
    for k, overrides in enumerate(RUNS[:3]):
        scene_file = tmp_path / f"run{k}.json"
        small_slope.with_overrides(overrides).save(scene_file)
        out = tmp_path / f"run{k}.h5"
        done = run_cli("run", scene_file, "--duration", duration, "-o", out, "--quiet")
        assert done.returncode == 0, done.stderr
        with h5py.File(out, "r") as f:
            recorded = f["particles/jelly/position/value"][()]
            recorded_t = f["particles/jelly/position/time"][()]
        assert recorded.shape == r.positions[k].shape
        assert recorded.tobytes() == r.positions[k].tobytes(), k
        assert recorded_t.tobytes() == r.times[k].tobytes(), k


def test_a_diverged_run_stops_alone(small_slope):
    runs = [{}, {"integrator.name": "explicit_euler", "integrator.dt": 0.02,
                 "springs.structural.ks": 1e6}, {"springs.bending.ks": 300}]
    r = jelly.rollout(small_slope, runs, 0.4, every=0.01, velocities=True)
    assert list(r.status) == ["completed", "diverged", "completed"]
    assert list(r.ok) == [True, False, True]
    assert r.reasons[1] and r.reasons[0] == "" and r.reasons[2] == ""
    kept = r.frames[1]
    assert 0 < kept < r.positions.shape[1] == r.frames[0] == r.frames[2]
    assert np.isnan(r.positions[1, kept:]).all() and np.isnan(r.velocities[1, kept:]).all()
    assert np.isnan(r.times[1, kept:]).all() and np.isfinite(r.times[1, :kept]).all()
    assert np.isfinite(r.positions[[0, 2]]).all()
    assert r.runs[1]["status"] == "diverged" and r.runs[1]["t"] < 0.4


def test_different_time_steps_pad_their_frames(small_slope):
    # A frame every 0.01 s: dt 0.003 reaches the frame times at 0.012, 0.021, ... and has fewer
    # frames by 0.1 s than dt 0.001; its last frames are NaN and `frames` says how many it kept.
    r = jelly.rollout(small_slope, [{}, {"integrator.dt": 0.003}], 0.1, every=0.01)
    assert r.frames[0] == 11 and r.positions.shape[1] == 11
    x, _, t, _ = alone(small_slope, {"integrator.dt": 0.003}, 0.1, 0.01)
    assert r.frames[1] == len(t) < 11
    assert r.positions[1, :len(t)].tobytes() == x.tobytes()
    assert np.isnan(r.positions[1, len(t):]).all()


def test_every_step_and_the_default_interval(small_slope):
    r = jelly.rollout(small_slope, [{}], 0.01, every=0)
    assert r.positions.shape == (1, 11, 125, 3) and r.velocities is None
    r = jelly.rollout(small_slope, [{}], 0.1)  # the scene's output_interval, 1/60 s
    assert r.positions.shape[1] == 7


def test_runs_of_other_particle_counts_are_refused(small_slope):
    with pytest.raises(jelly.InputError, match=r"overrides_per_run\[1\].*216 particles.*125"):
        jelly.rollout(small_slope, [{}, {"cube.n": 6}], 0.1)


def test_bad_overrides_name_the_run_and_the_field(small_slope):
    with pytest.raises(jelly.InputError,
                       match=r"overrides_per_run\[2\].*springs.structural.ks"):
        jelly.rollout(small_slope, [{}, {}, {"springs.structural.ks": -5}], 0.1)
    with pytest.raises(jelly.InputError, match=r"overrides_per_run\[0\].*duration"):
        jelly.rollout(small_slope, [{"duration": 3}], 0.1)
    with pytest.raises(jelly.InputError, match=r"overrides_per_run\[1\].*output_interval"):
        jelly.rollout(small_slope, [{}, ["output_interval=0.1"]], 0.1)
    with pytest.raises(jelly.InputError, match="duration"):
        jelly.rollout(small_slope, [{}], -1)
    with pytest.raises(jelly.InputError, match="every = -0.5"):
        jelly.rollout(small_slope, [{}], 0.1, every=-0.5)
    with pytest.raises(jelly.InputError, match="threads"):
        jelly.rollout(small_slope, [{}], 0.1, threads=-2)
    with pytest.raises(jelly.InputError, match="overrides_per_run"):
        jelly.rollout(small_slope, [], 0.1)
    with pytest.raises(TypeError, match="one item"):
        jelly.rollout(small_slope, {"gravity": [0, 0, 0]}, 0.1)


def test_a_scene_path_and_string_overrides(scenes):
    r = jelly.rollout(scenes / "seed_slope.json", [["cube.n=3", "springs.shear.ks=900"]], 0.05,
                      every=0.01)
    x, _, _, _ = alone(jelly.load_scene(scenes / "seed_slope.json"),
                       {"cube.n": 3, "springs.shear.ks": 900}, 0.05, 0.01)
    assert r.positions[0].tobytes() == x.tobytes()


def test_the_result_pickles_prints_and_owns_its_arrays(small_slope):
    r = jelly.rollout(small_slope, RUNS[:2], 0.05, every=0.01, velocities=True)
    assert repr(r) == "<jelly.Rollout 2 runs (2 ok), 6 frames of 125 particles, with velocities>"
    assert len(r) == 2
    positions = r.positions
    del r  # the array keeps the result alive
    assert np.isfinite(positions).all()
    r = jelly.rollout(small_slope, RUNS[:2], 0.05, every=0.01, velocities=True)
    back = pickle.loads(pickle.dumps(r))
    for name in ("positions", "velocities", "times", "frames", "steps", "ok"):
        assert getattr(back, name).tobytes() == getattr(r, name).tobytes(), name
    assert back.status == r.status and back.runs == r.runs
    # The arrays are views of the result's memory: no copy on each access.
    assert np.shares_memory(r.positions, r.positions)
    # Writeable NumPy arrays: DLPack hands them over without a copy.
    assert np.shares_memory(np.from_dlpack(r.positions), r.positions)


INTERRUPTED_ROLLOUT = textwrap.dedent("""
    import os, signal, sys, threading, time
    import jelly
    scene = jelly.load_scene(sys.argv[1], {"cube.n": 4, "terrains": [], "gravity": [0, 0, 0]})
    threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.perf_counter()
    try:
        jelly.rollout(scene, [{}] * 8, 1e4, every=10)  # 8 x 10^7 steps: hours
        print("not interrupted")
    except KeyboardInterrupt:
        print(f"interrupted after {time.perf_counter() - start:.1f} s")
""")


def test_ctrl_c_stops_a_rollout(scenes):
    result = subprocess.run([sys.executable, "-c", INTERRUPTED_ROLLOUT,
                             str(scenes / "seed_slope.json")], capture_output=True, text=True,
                            timeout=120, env=os.environ.copy())
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("interrupted after"), result.stdout


def test_every_integrator_runs_side_by_side_as_alone(scenes):
    # Two runs of each registered integrator at once (their solvers, SUNDIALS contexts and
    # factorizations on two threads), each equal to its simulator alone.
    scene = jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 3})
    runs = [{"integrator.name": name, "integrator.dt": 0.002} for name in jelly.integrator_names()]
    r = jelly.rollout(scene, runs * 2, 0.06, every=0.01, threads=2)
    assert set(r.status) == {"completed"}, r.reasons
    for k, overrides in enumerate(runs * 2):
        x, _, _, _ = alone(scene, overrides, 0.06, 0.01)
        assert r.positions[k].tobytes() == x.tobytes(), overrides
