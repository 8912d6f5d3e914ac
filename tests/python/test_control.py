"""A control loop from Python: reset() to a saved snapshot or state, step(n), observations as
read-only views that follow the simulator without copies, actions through the live model (pin
targets, gravity, forces). An episode after a reset repeats the first one bit for bit."""

import gc
import weakref

import numpy as np
import pytest

import jelly


def hanging_cube():
    spec = jelly.CubeSpec()
    spec.n, spec.edge_length, spec.origin = 3, 0.6, [-0.3, 1.0, -0.3]
    spec.particle_mass = 0.05
    options = jelly.SimulatorOptions()
    options.dt = 1 / 120
    sim = jelly.Simulator(jelly.build_cube(spec), None, "implicit_euler",
                          jelly.IntegratorOptions(), options)
    top = jelly.cube_index(3, 0, 2, 0)
    sim.set_pin(top)
    return sim, top


def episode(sim, top, steps=40, gain=2.0):
    """Drives the pin towards x = 1 with a proportional controller; the centre of mass after
    each step."""
    goal = np.array([1.0, 1.6, 0.0])
    path = []
    for _ in range(steps):
        pin = np.array(sim.state.x[top])
        sim.set_pin_target(top, pin, gain * (goal - pin))  # action
        assert sim.step().ok
        path.append(sim.center_of_mass())                    # observation
    return np.array(path)


def test_an_episode_after_reset_repeats_the_first_bit_for_bit():
    sim, top = hanging_cube()
    start = sim.snapshot()
    first = episode(sim, top)
    x_first = np.array(sim.state.x)
    assert np.linalg.norm(first[-1] - first[0]) > 0.1  # the controller moved it
    sim.reset(start)
    assert sim.t == 0 and sim.total_steps == 0
    second = episode(sim, top)
    assert second.tobytes() == first.tobytes()
    assert sim.state.x.tobytes() == x_first.tobytes()
    # And equal to a simulator that never ran before.
    fresh, _ = hanging_cube()
    assert episode(fresh, top).tobytes() == first.tobytes()


def test_reset_undoes_live_edits_made_after_the_snapshot():
    sim, top = hanging_cube()
    start = sim.snapshot()
    sim.set_gravity([0, 0, 0])
    sim.set_spring_coefficients(0, "structural", 5.0, 0.0)
    sim.set_pin_target(top, [0.5, 1.6, 0.0], [1.0, 0, 0])
    sim.step(10)
    sim.reset(start)
    fresh, _ = hanging_cube()
    sim.step(30)
    fresh.step(30)
    assert sim.state.x.tobytes() == fresh.state.x.tobytes()


def test_reset_to_a_state():
    sim, top = hanging_cube()
    sim.step(5)
    saved = jelly.State(np.array(sim.state.x), np.array(sim.state.v), sim.t)
    sim.step(20)
    sim.reset(saved)
    assert sim.t == saved.t and np.array_equal(sim.state.x, saved.x)
    with pytest.raises(jelly.InputError):
        sim.reset(jelly.State(np.zeros((2, 3)), np.zeros((2, 3)), 0.0))


def test_step_n_equals_n_single_steps():
    a, _ = hanging_cube()
    b, _ = hanging_cube()
    result = a.step(25)
    for _ in range(25):
        b.step()
    assert result.ok and a.total_steps == 25
    assert a.state.x.tobytes() == b.state.x.tobytes()
    assert a.state.v.tobytes() == b.state.v.tobytes()
    with pytest.raises(jelly.InputError, match="n"):
        a.step(0)


def test_step_n_stops_at_a_failed_step():
    sim, _ = hanging_cube()
    sim.add_force(Explodes())
    with pytest.raises(RuntimeError, match="boom"):
        sim.step(10)
    # Left at the last completed step, before t = 0.05 s.
    assert 3 <= sim.total_steps < 10
    assert sim.t == pytest.approx(sim.total_steps / 120, abs=1e-12)


class Explodes(jelly.Force):
    """Raises once the simulator's time reaches 0.05 s."""

    def forces(self, t, x, v, f):
        if t >= 0.05:
            raise RuntimeError("boom")


def test_observations_are_views_that_follow_the_simulator():
    sim, top = hanging_cube()
    x, v = sim.state.x, sim.state.v
    start = sim.snapshot()
    assert not x.flags.writeable and not v.flags.writeable
    with pytest.raises(ValueError):
        x[0, 0] = 1.0
    sim.step(10)
    assert np.shares_memory(x, sim.state.x) and np.array_equal(x, sim.state.x)
    moved = np.array(x)
    sim.reset(start)  # the views stay valid across a reset
    assert np.array_equal(x, start.state.x) and not np.array_equal(x, moved)
    # A view keeps its simulator alive.
    ref = weakref.ref(sim)
    del sim
    gc.collect()
    assert ref() is not None and np.isfinite(x).all()
    del x, v
    gc.collect()


def test_read_only_views_go_to_dlpack_without_a_copy():
    sim, _ = hanging_cube()
    x = sim.state.x
    with pytest.raises(BufferError):  # NumPy 1.24 does not export a read-only array
        x.__dlpack__()
    exported = jelly.dlpack(x)
    assert exported.__dlpack_device__() == (1, 0)
    taken = np.from_dlpack(exported)
    assert np.shares_memory(taken, x) and taken.shape == x.shape and taken.dtype == np.float64
    sim.step(3)
    assert np.array_equal(taken, sim.state.x)  # the same memory, after steps too
    # A strided view and the model's arrays.
    assert np.array_equal(np.from_dlpack(jelly.dlpack(x[:, 1])), x[:, 1])
    assert np.array_equal(np.from_dlpack(jelly.dlpack(sim.model.springs.a)), sim.model.springs.a)
    # The tensor keeps the simulator alive.
    ref = weakref.ref(sim)
    del sim, x, exported
    gc.collect()
    assert ref() is not None and np.isfinite(taken).all()
    del taken
    gc.collect()
    assert ref() is None
    with pytest.raises(jelly.InputError, match="stream"):
        jelly.dlpack(np.zeros(3)).__dlpack__(stream=1)


def test_the_pin_controller_example_resets_between_episodes():
    import os
    import pathlib
    import subprocess
    import sys
    source = pathlib.Path(os.environ.get("JELLY_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
    done = subprocess.run([sys.executable, str(source / "examples/python/pin_controller.py"),
                           "--seconds", "2", "--gains", "1,3"], capture_output=True, text=True,
                          check=True)
    lines = done.stdout.splitlines()
    first = lines[-3].split("the centre is ")[1]
    # Gain 1 from the start again repeats the first episode exactly; gain 3 differs.
    assert lines[-2] == "gain 1: after 2 s the centre is " + first, done.stdout
    assert lines[-1].startswith("gain 3: ") and lines[-1].split("is ")[1] != first
