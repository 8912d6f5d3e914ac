"""Simulation from Python: equal to `jelly run` bit for bit, NumPy views of the C++ state,
callbacks at every frame, reports (also of diverged runs), the GIL released while stepping."""

import copy
import pickle
import re
import threading
import weakref

import h5py
import numpy as np
import pytest

import jelly


def h5_contents(path):
    """Every dataset's data and every attribute of a file, except the wall-clock ones (wall,
    seconds, timings in ms)."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            for key, value in obj.attrs.items():
                if "wall" not in key and "seconds" not in key and not key.endswith("_ms"):
                    out[f"{name}@{key}"] = value
            if isinstance(obj, h5py.Dataset):
                out[name] = obj[()]
        f.visititems(visit)
        for key, value in f.attrs.items():
            out[f"@{key}"] = value
    return out


def assert_same_file(a, b):
    ca, cb = h5_contents(a), h5_contents(b)
    assert sorted(ca) == sorted(cb)
    for key in ca:
        va, vb = np.asarray(ca[key]), np.asarray(cb[key])
        assert va.dtype == vb.dtype and va.shape == vb.shape, key
        assert va.tobytes() == vb.tobytes(), key  # bit for bit (NaN-safe)


@pytest.mark.parametrize("scene_file,sets", [
    ("seed_slope.json", ["springs.shear.ks=1800"]),
    ("drop_coulomb.json", ["integrator.name=implicit_euler", "integrator.dt=0.01"]),
    # Bodies: two cubes (one changed by its bodies[i] path), a driven pin, a pinned cloth under
    # implicit Euler at 1/60, cubes stacked with body-body contact.
    ("two_jellies.json", ["bodies[1].springs.structural.ks=6000"]),
    ("pinned_jelly.json", []),
    ("hanging_cloth.json", []),
    ("jelly_stack.json", []),
])
def test_run_equals_jelly_run_bit_for_bit(scenes, run_cli, tmp_path, scene_file, sets):
    cli_file, py_file = tmp_path / "cli.h5", tmp_path / "py.h5"
    args = [a for s in sets for a in ("--set", s)]
    done = run_cli("run", scenes / scene_file, *args, "--duration", "0.4", "-o", cli_file,
                   "--quiet")
    assert done.returncode == 0, done.stderr

    scene = jelly.load_scene(scenes / scene_file, sets + ["duration=0.4"])
    sim = jelly.Simulator(scene)
    with jelly.H5Recorder(str(py_file), sim, scene) as recorder:
        sim.add_observer(recorder)
        report = sim.run_until(scene.duration)
    assert report.status == "completed" and report.ok
    assert_same_file(cli_file, py_file)


def test_state_views_alias_the_cpp_memory(scenes):
    sim = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json"))
    x = sim.state.x
    assert x.shape == (1000, 3) and x.dtype == np.float64
    assert np.shares_memory(x, sim.state.x)
    address = x.__array_interface__["data"][0]
    assert sim.state.x.__array_interface__["data"][0] == address
    assert not x.flags.writeable and not x.flags.owndata
    with pytest.raises(ValueError):
        x[0, 0] = 1.0
    before = x.copy()
    sim.step()
    assert not np.array_equal(x, before)  # the old view shows the new state
    assert np.array_equal(x, sim.state.x)

    # A write through the setter lands in the same memory and is seen by the next step.
    reference = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json"))
    reference.step()
    kicked = sim.state.v + np.array([0.0, 2.0, 0.5])
    sim.state.v = kicked
    assert np.array_equal(sim.state.v, kicked)
    assert sim.state.v.__array_interface__["data"][0] == \
        sim.state.v.__array_interface__["data"][0]
    reference.state = jelly.State(reference.state.x, kicked, reference.state.t)
    sim.step()
    reference.step()
    assert np.array_equal(sim.state.x, reference.state.x)
    assert np.array_equal(sim.state.v, reference.state.v)
    assert x.__array_interface__["data"][0] == address  # still the simulator's buffer
    with pytest.raises(jelly.InputError, match=r"state\.x .*shape \(1000, 3\)"):
        sim.state.x = np.zeros((10, 3))
    sim.state.x = sim.state.x.reshape(-1)  # flat (3N,) is accepted too


def test_views_keep_the_simulator_alive(scenes):
    sim = jelly.Simulator(jelly.load_scene(scenes / "drop_coulomb.json"))
    alive = weakref.ref(sim)
    x = sim.state.x
    ks = sim.model.springs.ks
    expected = x.copy()
    del sim
    assert alive() is not None  # the arrays hold it
    assert np.array_equal(x, expected) and ks.size > 0
    del x, ks
    assert alive() is None


def test_callback_sees_every_frame(scenes, tmp_path):
    scene = jelly.load_scene(scenes / "seed_slope.json", ["duration=0.5"])
    sim = jelly.Simulator(scene)
    seen = []

    def callback(s):
        assert s is sim
        seen.append((s.t, s.state.x.copy()))

    with jelly.H5Recorder(str(tmp_path / "r.h5"), sim, scene) as recorder:
        sim.add_observer(recorder)
        report = sim.run_until(0.5, callback=callback)
    assert report.ok
    recording = jelly.read_recording(str(tmp_path / "r.h5"))
    assert len(seen) == recording.frames == 31  # t = 0, 1/60, ..., 0.5
    assert np.array_equal([t for t, _ in seen], recording.time)
    for k, (_, x) in enumerate(seen):
        assert np.array_equal(x, recording.position[k])
    # The callback is called only during its run.
    sim.remove_observer(recorder)
    sim.run_until(0.6)
    assert len(seen) == 31


def test_callback_exception_propagates_and_the_simulator_goes_on(scenes):
    sim = jelly.Simulator(jelly.load_scene(scenes / "drop_coulomb.json"))

    def fail(s):
        if s.t > 0.05:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        sim.run_until(1.0, callback=fail)
    t = sim.t
    assert 0.05 < t < 0.1
    assert sim.run_until(t + 0.1).ok


def test_python_observer(scenes):
    class Counter(jelly.Observer):
        def __init__(self):
            super().__init__()
            self.frames, self.reports = 0, []

        def on_frame(self, simulator):
            self.frames += 1

        def on_finish(self, simulator, report):
            self.reports.append(report.status)

    sim = jelly.Simulator(jelly.load_scene(scenes / "drop_coulomb.json"))
    counter = Counter()
    sim.add_observer(counter)
    sim.run_until(0.5)
    assert counter.reports == ["completed"] and counter.frames == 31
    sim.remove_observer(counter)
    sim.run_until(1.0)
    assert counter.frames == 31


def test_diverged_run_returns_a_report(scenes):
    scene = jelly.load_scene(scenes / "seed_slope.json", {
        "integrator.name": "explicit_euler", "integrator.dt": 0.02, "duration": 5})
    report = jelly.Simulator(scene).run_until(5.0)
    assert report.status == "diverged" and not report.ok
    assert report.t < 5.0 and report.reason
    d = report.as_dict()
    assert d["status"] == "diverged" and d["t"] == report.t and "steps" in d["statistics"]


def test_measures_statistics_and_model(scenes):
    sim = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json"))
    assert np.allclose(sim.center_of_mass(), [-2 / 9, 79 / 9, -2 / 9])
    assert sim.kinetic_energy() == 0 and sim.elastic_energy() == 0
    assert sim.total_energy() == pytest.approx(sim.gravitational_energy())
    assert np.array_equal(sim.linear_momentum(), [0, 0, 0])
    assert jelly.total_energy(sim.model, sim.state) == sim.total_energy()
    model = sim.model
    assert model.num_particles == 1000 and model.mass.sum() == 1000
    springs = model.springs
    assert len(springs) == model.num_springs == 12876
    assert [springs.count(t) for t in ("structural", "shear", "bending")] == [2700, 7776, 2400]
    assert springs.a.dtype == np.int32 and springs.type.dtype == np.uint8
    assert not springs.ks.flags.writeable
    assert set(jelly.integrator_names()) >= {"explicit_euler", "implicit_euler", "midpoint", "rk4"}
    assert "rk4" in jelly.integrator_infos()
    sim.run_until(0.1)
    assert sim.integrator.statistics()["steps"] == 100
    assert sim.integrator.name == "rk4" and sim.total_steps == 100


def test_simulator_from_code_equals_the_same_scene():
    spec = jelly.CubeSpec()
    spec.n = 4
    spec.set_springs("shear", 900, 20)
    model = jelly.build_cube(spec)
    options = jelly.SimulatorOptions()
    options.dt = 0.002
    options.output_interval = 0.1
    sim = jelly.Simulator(model, integrator="midpoint", options=options)
    sim.add_terrain(jelly.Plane.slope(20))
    assert sim.run_until(0.5).ok
    # The same run from a scene gives the same numbers.
    scene = jelly.Scene({"cube": {"n": 4}, "springs": {"shear": {"ks": 900, "kd": 20}},
                         "terrains": [{"kind": "slope"}], "duration": 0.5,
                         "integrator": {"name": "midpoint", "dt": 0.002}, "output_interval": 0.1})
    other = jelly.Simulator(scene)
    other.run_until(0.5)
    assert np.array_equal(sim.state.x, other.state.x)
    with pytest.raises(jelly.InputError, match='integrator.name = "rk5" is invalid'):
        jelly.Simulator(model, integrator="rk5")


def test_run_until_releases_the_gil(scenes):
    sim = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json"))
    started = threading.Event()

    def run():
        started.set()
        sim.run_until(0.3)

    thread = threading.Thread(target=run)
    thread.start()
    started.wait()
    spins = 0
    while thread.is_alive():
        spins += 1
    thread.join()
    # With the GIL held by run_until this loop could not run while the thread simulates.
    assert spins > 10000


def test_anchor_springs_pull_particles(scenes):
    scene = jelly.load_scene(scenes / "drop_coulomb.json", {"gravity": [0, 0, 0], "terrains": []})
    sim = jelly.Simulator(scene)
    start = sim.center_of_mass()
    target = sim.state.x[0] + np.array([1.0, 0.0, 0.0])
    sim.set_anchors([jelly.AnchorSpring(0, target, stiffness=200.0, damping=1.0)])
    assert sim.anchors[0].particle == 0 and np.array_equal(sim.anchors[0].target, target)
    assert sim.run_until(0.5).ok
    assert sim.center_of_mass()[0] > start[0] + 1e-3  # pulled along +x
    sim.set_anchors([])
    assert sim.anchors == []
    with pytest.raises(jelly.InputError):
        sim.set_anchors([jelly.AnchorSpring(10**6, target, 1.0)])


def test_missed_tolerance_is_completed_with_warnings_as_in_jelly_run(scenes, run_cli):
    # The small slope with coulomb contact at 1/60 s and Newton cut to 5 iterations (the CLI test
    # SilentNumericalFailure.NewtonStoppedAboveItsToleranceIsAWarningCountedInTheSummary): the
    # module reports the same status and the same count of missed steps as the jelly program.
    sets = ["cube.n=3", "integrator.name=implicit_euler", "integrator.dt=0.0166667",
            "duration=3", "integrator.options.newton_iterations=5",
            "terrains[0].contact.model=coulomb"]
    args = [a for s in sets for a in ("--set", s)]
    done = run_cli("run", scenes / "seed_slope.json", *args)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("jelly run: completed_with_warnings at t = ")
    missed = int(re.search(r"newton_not_converged = (\d+)", done.stdout).group(1))
    assert missed > 0

    scene = jelly.load_scene(scenes / "seed_slope.json", sets)
    report = jelly.Simulator(scene).run_until(scene.duration)
    assert report.status == "completed_with_warnings" and report.ok
    assert report.statistics["newton_not_converged"] == missed
    assert f"on {missed} of 180 steps" in report.reason


def test_arkode_linear_solver_is_one_of_its_table():
    options = jelly.IntegratorOptions()
    assert options.arkode.linear_solver == "auto"
    for name in ["auto", "cg", "jacobi", "gmres", "schur", "klu"]:
        options.arkode.linear_solver = name
        assert options.arkode.linear_solver == name
    with pytest.raises(ValueError, match="linear_solver"):
        options.arkode.linear_solver = "lu"


def test_multigrid_preconditioner_is_an_option_and_follows_block_jacobi():
    # cg_preconditioner = "multigrid" on the matrix-free path (an 8^3 cube, stretched, falling freely),
    # and "amg" on the assembled one: the same motion as block Jacobi to a tight CG tolerance, in
    # fewer CG iterations.
    options = jelly.IntegratorOptions()
    assert options.implicit.cg_preconditioner == "jacobi"
    with pytest.raises(ValueError, match="cg_preconditioner"):
        options.implicit.cg_preconditioner = "ilu"
    runs = {}
    for name in ["jacobi", "multigrid", "amg"]:
        options = jelly.IntegratorOptions()
        options.implicit.cg_preconditioner = name
        options.implicit.cg_tolerance = 1e-10
        assert options.implicit.cg_preconditioner == name
        spec = jelly.CubeSpec()
        spec.n, spec.edge_length, spec.origin = 8, 1.0, [0.0, 2.0, 0.0]
        model = jelly.build_cube(spec)
        state = jelly.rest_state(model)
        x = np.array(state.x)
        x[:, 0] *= 1.1  # stretched: the springs work
        state.x = x
        sim_options = jelly.SimulatorOptions()
        sim_options.dt = 1 / 60
        sim = jelly.Simulator(model, state, "implicit_euler", options, sim_options)
        report = sim.run_until(0.25)
        assert report.ok, report.brief()
        runs[name] = (np.array(sim.state.x), report.statistics["cg_iterations"])
    assert np.abs(runs["multigrid"][0] - runs["jacobi"][0]).max() < 1e-7
    assert runs["multigrid"][1] < runs["jacobi"][1]
    # "amg" (smoothed aggregation on the assembled matrix) follows them as well.
    assert np.abs(runs["amg"][0] - runs["jacobi"][0]).max() < 1e-7
    assert runs["amg"][1] < runs["jacobi"][1]


def test_contact_screening_equals_jelly_run_and_is_validated(scenes, run_cli, tmp_path):
    # implicit_euler's contact_screening_tolerance on the matrix-free path (8^3 particles
    # lowered onto the coulomb slope): the module's run is the jelly program's bit for bit, with
    # the same statistics, and screening adds finishing solves to the unscreened run's.
    sets = ["cube.n=8", "cube.origin=[-2.2222222,0.7,-2.2222222]",
            "integrator.name=implicit_euler", "integrator.dt=0.0166666666666667", "duration=0.5",
            "terrains[0].contact.model=coulomb"]
    screened = sets + ["integrator.options.contact_screening_tolerance=0.01"]
    sets = sets + ["integrator.options.contact_screening_tolerance=0"]

    def cli_solves(scene_sets, path):
        args = [a for s in scene_sets for a in ("--set", s)]
        done = run_cli("run", scenes / "seed_slope.json", *args, "-o", path, "--quiet")
        assert done.returncode == 0, done.stderr
        return int(re.search(r"linear_solves = (\d+)", done.stdout).group(1))

    plain_solves = cli_solves(sets, tmp_path / "plain.h5")
    cli_file, py_file = tmp_path / "cli.h5", tmp_path / "py.h5"
    screened_solves = cli_solves(screened, cli_file)
    assert screened_solves > plain_solves

    scene = jelly.load_scene(scenes / "seed_slope.json", screened)
    sim = jelly.Simulator(scene)
    with jelly.H5Recorder(str(py_file), sim, scene) as recorder:
        sim.add_observer(recorder)
        report = sim.run_until(scene.duration)
    assert report.status == "completed" and report.ok
    assert report.statistics["linear_solves"] == screened_solves
    assert_same_file(cli_file, py_file)

    options = jelly.IntegratorOptions()
    assert options.implicit.contact_screening_tolerance == 0.001
    options.implicit.contact_screening_tolerance = 0.01
    assert options.implicit.contact_screening_tolerance == 0.01
    options.implicit.contact_screening_tolerance = 1.5
    model = jelly.build_cube(jelly.CubeSpec())
    with pytest.raises(jelly.InputError, match="contact_screening_tolerance = 1.5 is invalid"):
        jelly.Simulator(model, integrator="implicit_euler", integrator_options=options)


def test_members_documented_as_copies_are_copies(scenes):
    # Writes to them changed the simulator without validation (issue 38).
    sim = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json"))
    sim.options.dt = 5.0
    sim.options.output_interval = -3
    sim.options.divergence.max_speed = -1
    assert sim.options.dt != 5.0 and sim.options.output_interval >= 0
    assert sim.options.divergence.max_speed == 500
    sim.terrains[0].contact.restitution = 5.0
    assert sim.terrains[0].contact.restitution <= 1
    with pytest.raises(jelly.InputError, match=r"contact\.restitution = 5"):
        contact = sim.terrains[0].contact
        contact.restitution = 5.0
        sim.terrains[0].contact = contact  # the validated way
    elevator = jelly.Elevator()
    elevator.spec.size_x = -4
    assert elevator.spec.size_x == 5
    snapshot = sim.snapshot()
    snapshot.state.t = 99
    assert snapshot.state.t == 0


def test_pickling_copies_and_reprs(scenes):
    scene = jelly.load_scene(scenes / "seed_slope.json")
    sim = jelly.Simulator(scene)
    report = sim.run_until(0.01)
    state = copy.deepcopy(sim.state)
    assert np.array_equal(state.x, sim.state.x) and not np.shares_memory(state.x, sim.state.x)
    again = pickle.loads(pickle.dumps(sim.state))
    assert again.t == sim.t and np.array_equal(again.v, sim.state.v)
    assert repr(pickle.loads(pickle.dumps(report))) == repr(report)
    # A pickled snapshot restores bit for bit.
    snapshot = pickle.loads(pickle.dumps(sim.snapshot()))
    sim.run_until(0.02)
    x = np.array(sim.state.x)
    sim.restore(snapshot)
    sim.run_until(0.02)
    assert np.array_equal(sim.state.x, x)
    options = jelly.SimulatorOptions()
    options.dt = 0.002
    options.divergence.max_speed = 40
    spec = jelly.CubeSpec()
    spec.set_springs("shear", 10, 2)
    for value in (options, spec, jelly.IntegratorOptions(), jelly.ContactParams(),
                  jelly.ElevatorSpec(), jelly.RecorderOptions(), jelly.FitOptions(),
                  jelly.AnchorSpring(3, [0, 1, 0], 20)):
        copied = pickle.loads(pickle.dumps(value))
        assert repr(copied) == repr(value) and type(copied) is type(value)
    assert pickle.loads(pickle.dumps(spec)).springs("shear").ks == 10
    assert "dt=0.002" in repr(options) and "max_speed=40" in repr(options)
    assert repr(sim).startswith("<jelly.Simulator rk4")
    assert repr(sim.integrator).startswith("<jelly.Integrator rk4")
    assert repr(sim.model.springs) == "<jelly.Springs 12876 springs>"
    assert repr(sim.model.pins).startswith("<jelly.Pins 0 particles")
    assert "jelly.InputError" not in (jelly.InputError.__doc__ or "") and jelly.InputError.__doc__


def test_a_simulator_of_a_model_chooses_its_threads():
    options = jelly.SimulatorOptions()
    options.threads = 1
    sim = jelly.Simulator(jelly.build_cube(jelly.CubeSpec()), options=options)
    assert sim.options.threads == 1
    sim.set_threads(2)
    assert sim.options.threads == 2
    with pytest.raises(jelly.InputError):
        sim.set_threads(-1)
