"""Recordings from Python: H5Recorder, read_recording as NumPy arrays, checkpoints and restarts
that continue bit for bit."""

import h5py
import numpy as np
import pytest

import jelly


def record(scene, path, t_end, options=None):
    sim = jelly.Simulator(scene)
    recorder = jelly.H5Recorder(str(path), sim, scene, options)
    sim.add_observer(recorder)
    report = sim.run_until(t_end)
    recorder.close()
    return sim, report


def test_read_recording_returns_arrays(scenes, tmp_path):
    scene = jelly.load_scene(scenes / "seed_elevator.json", ["duration=0.5"])
    sim, report = record(scene, tmp_path / "e.h5", 0.5)
    assert report.ok
    rec = jelly.read_recording(str(tmp_path / "e.h5"))
    assert rec.frames == 31
    assert rec.time.shape == (31,) and rec.step.shape == (31,)
    assert rec.position.shape == rec.velocity.shape == (31, 1000, 3)
    assert rec.position is rec.position  # built once
    assert np.array_equal(rec.position[-1], sim.state.x)
    assert np.array_equal(rec.velocity[-1], sim.state.v)
    with h5py.File(tmp_path / "e.h5", "r") as f:
        assert np.array_equal(rec.position, f["particles/jelly/position/value"][()])
        assert np.array_equal(rec.observables["center_of_mass"],
                              f["observables/center_of_mass/value"][()])
    assert rec.observables["total_energy"].shape == (31,)
    assert rec.observables["center_of_mass"].shape == (31, 3)
    assert rec.attributes["run_status"] == "completed"
    assert rec.scene == scene
    assert rec.terrains[0]["kind"] == "elevator" and rec.terrains[0]["position"].shape == (31, 3)
    assert rec.model.num_particles == 1000
    assert "frames" in jelly.describe_recording(str(tmp_path / "e.h5"))


def test_checkpoint_restart_is_bit_for_bit(scenes, tmp_path):
    scene = jelly.load_scene(scenes / "seed_slope.json", ["duration=1.2"])
    whole = jelly.Simulator(scene)
    assert whole.run_until(1.2).ok

    _, first = record(scene, tmp_path / "first.h5", 0.7)
    checkpoint = jelly.read_checkpoint(str(tmp_path / "first.h5"))
    assert checkpoint.integrator == "rk4" and checkpoint.state.t == pytest.approx(0.7)
    resumed = jelly.Simulator(scene)
    jelly.restore(resumed, checkpoint)
    assert resumed.run_until(1.2).ok
    assert np.array_equal(resumed.state.x, whole.state.x)
    assert np.array_equal(resumed.state.v, whole.state.v)

    # In memory: snapshot and restore.
    a = jelly.Simulator(scene)
    a.run_until(0.5)
    snap = a.snapshot()
    a.run_until(0.9)
    b = jelly.Simulator(scene)
    b.restore(snap)
    b.run_until(0.9)
    assert np.array_equal(a.state.x, b.state.x)

    jelly.check_same_scene(checkpoint, scene.with_overrides({"duration": 5}))
    with pytest.raises(jelly.InputError, match=r"springs\.structural\.ks"):
        jelly.check_same_scene(checkpoint, scene.with_overrides({"springs.structural.ks": 9}))
    other = jelly.Simulator(scene.with_overrides({"integrator.name": "midpoint"}))
    with pytest.raises(jelly.InputError, match="integrator"):
        jelly.restore(other, checkpoint)


def test_recorder_errors_and_close(scenes, tmp_path):
    scene = jelly.load_scene(scenes / "drop_coulomb.json")
    sim = jelly.Simulator(scene)
    with pytest.raises(jelly.InputError):
        jelly.H5Recorder(str(tmp_path / "no" / "such" / "dir.h5"), sim)
    options = jelly.RecorderOptions()
    options.compression_level = 0
    options.write_xdmf = False
    recorder = jelly.H5Recorder(str(tmp_path / "r.h5"), sim, None, options)
    sim.add_observer(recorder)
    sim.run_until(0.1)
    recorder.close()
    assert recorder.closed and recorder.frames == 7
    # Closing removed it from the simulator (issue 38): the next run goes on without it.
    assert not sim.remove_observer(recorder)
    assert sim.run_until(0.3).ok
    with pytest.raises(jelly.InputError, match="is closed"):
        sim.add_observer(recorder)
    rec = jelly.read_recording(str(tmp_path / "r.h5"))
    assert rec.frames == 7 and rec.scene_json == ""
    assert not (tmp_path / "r.xdmf").exists()
    with pytest.raises(jelly.InputError):
        rec.scene
    with pytest.raises(jelly.InputError):
        jelly.read_recording(str(tmp_path / "missing.h5"))
    # An existing file is replaced only when told to.
    with pytest.raises(jelly.InputError):
        jelly.H5Recorder(str(tmp_path / "r.h5"), jelly.Simulator(scene))
    options.overwrite = True
    jelly.H5Recorder(str(tmp_path / "r.h5"), jelly.Simulator(scene), None, options).close()


def test_a_recording_s_bodies_and_their_surfaces(scenes, tmp_path):
    # Each body is read back with its name, kind, particle range and render surface; its
    # surface vertices computed from the recorded positions are those the recorder stored
    # frame by frame (/particles/<body>/surface/position/value).
    scene = jelly.load_scene(scenes / "two_jellies.json", ["duration=0.3"])
    sim, report = record(scene, tmp_path / "two.h5", 0.3)
    assert report.ok
    rec = jelly.read_recording(str(tmp_path / "two.h5"))
    assert [(b.name, b.kind, b.particles) for b in rec.model.bodies] == [
        (b.name, b.kind, b.particles) for b in sim.model.bodies]
    with h5py.File(tmp_path / "two.h5", "r") as f:
        for body in rec.model.bodies:
            group = f["particles"][body.name]
            assert np.array_equal(body.surface.triangles, group["surface/triangles"][()])
            stored = group["surface/position/value"][()]
            assert stored.shape == (rec.frames, body.surface.num_vertices, 3)
            for k in (0, rec.frames - 1):
                assert np.allclose(body.surface_vertices(rec.position[k]), stored[k],
                                   rtol=0, atol=1e-12)
    last = rec.model.body("stiff").surface_vertices(rec.position[-1])
    assert np.array_equal(last, sim.model.body("stiff").surface_vertices(sim.state))


def test_the_with_block_of_the_docs_leaves_no_recorder_attached(scenes, tmp_path):
    scene = jelly.load_scene(scenes / "drop_coulomb.json", {"duration": 0.05})
    sim = jelly.Simulator(scene)
    with jelly.H5Recorder(str(tmp_path / "slope.h5"), sim, scene) as recorder:
        sim.add_observer(recorder)
        sim.run_until(scene.duration)
    assert sim.run_until(0.1).ok  # raised "is closed" before
    assert jelly.read_recording(str(tmp_path / "slope.h5")).frames == recorder.frames


def test_a_recorder_refuses_another_simulator(scenes, tmp_path):
    small = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 2}))
    large = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 30}))
    recorder = jelly.H5Recorder(str(tmp_path / "large.h5"), large)
    with pytest.raises(jelly.InputError, match=r"simulator = 8 particles.*27000 particles"):
        small.add_observer(recorder)
    with pytest.raises(ValueError, match="large.h5"):
        small.add_observer(recorder)
    assert small.run_until(0.01).ok  # nothing attached
    # The same particle count in other bodies: refused too, naming them.
    two = jelly.Simulator(jelly.load_scene(scenes / "two_jellies.json"))
    renamed = jelly.Simulator(jelly.load_scene(scenes / "two_jellies.json",
                                               {"bodies[0].name": "other"}))
    two_recorder = jelly.H5Recorder(str(tmp_path / "two.h5"), two)
    with pytest.raises(jelly.InputError, match=r"\(other, stiff\).*\(soft, stiff\)"):
        renamed.add_observer(two_recorder)
    two.add_observer(two_recorder)  # its own simulator
    two_recorder.close()
    recorder.close()


def test_recordings_pickle_by_their_path(scenes, tmp_path):
    import pickle
    scene = jelly.load_scene(scenes / "drop_coulomb.json")
    record(scene, str(tmp_path / "r.h5"), 0.05)
    rec = jelly.read_recording(str(tmp_path / "r.h5"))
    again = pickle.loads(pickle.dumps(rec))
    assert again.path == rec.path == str(tmp_path / "r.h5")
    assert np.array_equal(again.position, rec.position)
