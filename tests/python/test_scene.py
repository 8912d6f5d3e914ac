"""Scenes: loading with overrides, fields as attributes by JSON path, validation by the C++
parser on every write, JSON out."""

import copy
import json
import os
import pickle

import pytest

import jelly


def test_fields_read_as_attributes(scenes):
    scene = jelly.load_scene(scenes / "seed_slope.json")
    assert scene.springs.structural.ks == 1400
    assert scene.integrator.name == "rk4"
    assert scene.integrator.dt == 0.001
    assert scene.terrains[0].kind == "slope"
    assert scene.terrains[0].contact.model == "seed"
    assert len(scene.terrains) == 1
    assert scene.gravity == [0, -9.8, 0]
    assert scene.cube.n == 10
    # Defaults the file does not write are there too (the C++ scene_to_json writes them all).
    assert scene.divergence.max_speed == 500
    assert scene.get("terrains[0].contact.restitution") == 0.8
    assert scene.get("terrains.0.angle_degrees") == 20
    with pytest.raises(AttributeError, match="no field 'cubes'"):
        scene.cubes
    with pytest.raises(KeyError):
        scene.get("terrains[3].kind")


def test_writes_are_validated_and_reach_the_cpp_scene(scenes):
    scene = jelly.load_scene(scenes / "seed_slope.json")
    scene.springs.structural.ks = 2400
    scene.terrains[0].contact.restitution = 0.5
    scene.integrator.dt = 5e-4
    scene.gravity = [0, -3.0, 0]
    scene.gravity[0] = 1.0
    assert scene.springs.structural.ks == 2400
    assert scene.terrains[0].contact.restitution == 0.5
    assert scene.gravity == [1.0, -3.0, 0]
    # The C++ scene sees them: the simulator it builds has them.
    sim = jelly.Simulator(scene)
    ks = sim.model.springs.ks[sim.model.springs.type == 0]
    assert (ks == 2400).all()
    assert sim.options.dt == 5e-4
    assert list(sim.model.gravity) == [1.0, -3.0, 0]
    assert sim.terrains[0].contact.restitution == 0.5
    # Switching integrator: its options appear with their defaults.
    scene.integrator.name = "implicit_euler"
    assert scene.integrator.options.newton_iterations == 1
    scene.integrator.options.newton_iterations = 3
    assert jelly.Simulator(scene).integrator.name == "implicit_euler"


def test_bad_value_raises_input_error_with_the_json_path(scenes):
    scene = jelly.load_scene(scenes / "seed_slope.json")
    before = scene.to_json()
    with pytest.raises(jelly.InputError) as e:
        scene.terrains[0].contact.restitution = 1.5
    assert str(e.value) == "terrains[0].contact.restitution = 1.5 is invalid: a number in [0, 1]"
    assert isinstance(e.value, ValueError)
    assert scene.to_json() == before  # unchanged
    with pytest.raises(jelly.InputError, match=r"springs\.shear\.kb = 1 is invalid: unknown key"):
        scene.springs.shear.kb = 1
    with pytest.raises(jelly.InputError, match="integrator.name"):
        scene.integrator.name = "rk5"
    with pytest.raises(jelly.InputError, match=r"cube\.n"):
        scene.update({"cube.n": 1})
    assert scene.to_json() == before


def test_load_scene_overrides_and_bad_files(scenes, tmp_path):
    a = jelly.load_scene(scenes / "seed_slope.json", ["springs.structural.ks=2000",
                                                      "integrator.name=midpoint"])
    b = jelly.load_scene(scenes / "seed_slope.json", {"springs.structural.ks": 2000,
                                                      "integrator.name": "midpoint"})
    assert a == b
    assert a.springs.structural.ks == 2000 and a.integrator.name == "midpoint"
    with pytest.raises(jelly.InputError,
                       match=r"terrains\[0\]\.contact\.restitution = 2 is invalid"):
        jelly.load_scene(scenes / "seed_slope.json", ["terrains[0].contact.restitution=2"])
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"integrator": {"name": "rk4"}, "duration": 1,
                               "terrains": [{"kind": "slope", "angle_degrees": 95}]}))
    with pytest.raises(jelly.InputError, match=r"terrains\[0\]\.angle_degrees = 95 is invalid"):
        jelly.load_scene(bad)
    bad.write_text("{ not json")
    with pytest.raises(jelly.InputError, match="is not valid JSON"):
        jelly.load_scene(bad)
    with pytest.raises(jelly.InputError, match="cannot read the scene file"):
        jelly.load_scene(tmp_path / "missing.json")


def test_load_scene_refuses_a_pipe_without_blocking(tmp_path):
    fifo = tmp_path / "scene.json"
    os.mkfifo(fifo)
    with pytest.raises(jelly.InputError, match="it is a pipe, not a file"):
        jelly.load_scene(fifo)


def test_to_json_round_trip_equals_cpp(scenes):
    scene = jelly.load_scene(scenes / "seed_elevator.json")
    assert jelly.Scene(scene.to_json()) == scene
    assert scene.to_json() == jelly._jelly._load_scene(str(scenes / "seed_elevator.json")).to_json()
    assert jelly.Scene(scene.to_dict()) == scene
    copied = copy.deepcopy(scene)
    copied.duration = 1
    assert scene.duration == 8 and copied.duration == 1
    restored = pickle.loads(pickle.dumps(copied))
    assert restored == copied and isinstance(restored, jelly.Scene)
    assert scene.with_overrides({"duration": 2}).duration == 2


def test_scene_from_a_dict_with_only_what_is_required():
    scene = jelly.Scene({"integrator": {"name": "rk4"}, "duration": 1})
    assert scene.bodies[0].kind == "cube" and scene.bodies[0].n == 10
    assert scene.terrains.to_list() == []
    with pytest.raises(jelly.InputError, match="duration is missing"):
        jelly.Scene({"integrator": {"name": "rk4"}})


def test_bodies_read_and_write_by_their_json_paths(scenes):
    scene = jelly.load_scene(scenes / "two_jellies.json")
    assert [b.name for b in scene.bodies] == ["soft", "stiff"]
    assert scene.bodies[1].springs.structural.ks == 5000
    scene.bodies[0].springs.structural.ks = 700
    scene.bodies[1].n = 4
    sim = jelly.Simulator(scene)
    soft, stiff = sim.model.bodies
    assert (soft.name, soft.num_particles, stiff.num_particles) == ("soft", 6**3, 4**3)
    springs = sim.model.springs
    ks = springs.ks[soft.first_spring:soft.first_spring + soft.num_springs]
    structural = springs.type[soft.first_spring:soft.first_spring + soft.num_springs] == 0
    assert (ks[structural] == 700).all()
    with pytest.raises(jelly.InputError, match=r"bodies\[1\]\.n = 1 is invalid"):
        scene.bodies[1].n = 1
    assert scene.bodies[1].n == 4


def test_a_one_cube_file_reads_as_written_and_as_bodies(scenes):
    # seed_slope.json describes its cube with the top-level keys "cube" and "springs"; the
    # full JSON writes it as bodies[0]. Both paths read; a write to the file's own keys is seen
    # in bodies[0]; a write to bodies[0] turns the scene into its full JSON (no "springs" key).
    scene = jelly.load_scene(scenes / "seed_slope.json")
    assert scene.cube.n == 10 and scene.bodies[0].n == 10
    assert scene.bodies[0].name == "jelly" and scene.bodies[0].kind == "cube"
    scene.springs.shear.kd = 40
    assert scene.bodies[0].springs.shear.kd == 40
    scene.bodies[0].springs.shear.kd = 30
    assert scene.bodies[0].springs.shear.kd == 30
    assert "springs" not in json.loads(scene.source_json)
    springs = jelly.Simulator(scene).model.springs
    assert (springs.kd[springs.type == 1] == 30).all()
    # Overrides by either path, also when loading (as sweeps make their points).
    a = jelly.load_scene(scenes / "seed_slope.json", {"bodies[0].n": 4})
    b = jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 4})
    assert a == b and jelly.Simulator(a).model.num_particles == 64


def test_mesh_paths_are_relative_to_the_scene_file_from_any_cwd(scenes, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # not the source tree: "../assets/..." resolves elsewhere
    for name in ("gummy_bear.json", "bear_in_bowl.json"):
        scene = jelly.load_scene(scenes / name)
        assert scene.base_directory == str(scenes)
        # What sweeps and Dask do: copies, overrides, pickles re-parse with the same folder.
        again = pickle.loads(pickle.dumps(scene))
        assert again == scene and again.base_directory == scene.base_directory
        scene.update({"duration": 0.01})
        assert scene.with_overrides({"duration": 0.02}).duration == 0.02
    sim = jelly.Simulator(jelly.load_scene(scenes / "gummy_bear.json"))
    assert sim.model.num_particles > 0
    # The worker's function of a sweep, from this other cwd.
    scene = jelly.load_scene(scenes / "gummy_bear.json")
    row = jelly._sweep.run_point(scene.source_json, scene._name, {}, None, 0.002, None,
                                 scene.base_directory)
    assert row["status"] == "completed", row["reason"]


def test_numbers_of_a_one_cube_file_read_as_the_parser_reads_them(scenes):
    scene = jelly.load_scene(scenes / "seed_slope.json")  # "ks": 1400 in the file
    assert type(scene.springs.structural.ks) is float and scene.springs.structural.ks == 1400.0
    assert type(scene.cube.edge_length) is float
    assert scene.cube.n == 10 and type(scene.cube.n) is int
