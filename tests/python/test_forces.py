"""Forces written in Python inside every integrator, and the live model: edits between steps
without rebuilding the simulator (the same checks as the C++ tests in tests/solvers/)."""

import numpy as np
import pytest
import scipy.sparse

import jelly


def free_cube(n=4, integrator="rk4", dt=1e-3, options=None):
    """A free cube (no terrain), stretched along x so that its springs work."""
    spec = jelly.CubeSpec()
    spec.n, spec.edge_length, spec.origin = n, 1.0, [0.0, 2.0, 0.0]
    model = jelly.build_cube(spec)
    state = jelly.rest_state(model)
    x = np.array(state.x)
    x[:, 0] *= 1.1
    state.x = x
    sim_options = jelly.SimulatorOptions()
    sim_options.dt = dt
    return jelly.Simulator(model, state, integrator,
                           options if options is not None else jelly.IntegratorOptions(),
                           sim_options)


class AntiGravity(jelly.Force):
    """-m g on every particle."""

    def __init__(self, mass, gravity):
        super().__init__()
        self.weight = np.outer(mass, gravity)

    def forces(self, t, x, v, f):
        f -= self.weight


class SpringsToAnchors(jelly.Force):
    """Every particle pulled by a spring k to its rest position shifted by `shift`."""

    name = "springs_to_anchors"

    def __init__(self, anchors, k):
        super().__init__()
        self.anchors, self.k = np.array(anchors), k

    def forces(self, t, x, v, f):
        f -= self.k * (x - self.anchors)

    def energy(self, x):
        return 0.5 * self.k * np.sum((x - self.anchors) ** 2)


class SpringsToAnchorsWithJacobian(SpringsToAnchors):
    def jacobians(self, t, x, v):
        return -self.k * scipy.sparse.identity(x.size, format="csr"), None


def implicit(linear_solver):
    options = jelly.IntegratorOptions()
    options.implicit.linear_solver = linear_solver
    return options


@pytest.mark.parametrize("integrator,n,dt,options", [
    ("rk4", 4, 1e-3, None),
    ("implicit_euler", 4, 1 / 60, implicit("cholmod")),
    ("implicit_euler", 8, 1 / 60, implicit("auto")),  # > 1,000 unknowns: matrix-free CG
    ("xpbd", 4, 1 / 60, None),
    ("projective_dynamics", 4, 1 / 60, None),
])
def test_a_python_force_cancelling_gravity_keeps_the_centre_still(integrator, n, dt, options):
    sim = free_cube(n, integrator, dt, options)
    start = sim.center_of_mass()
    sim.add_force(AntiGravity(sim.model.mass, [0.0, -9.8, 0.0]))
    report = sim.run_until(1.0)
    assert report.ok, report.brief()
    assert np.linalg.norm(sim.center_of_mass() - start) < 1e-9
    assert sim.kinetic_energy() + sim.elastic_energy() > 0  # the springs worked
    # Without it the cube falls.
    fallen = free_cube(n, integrator, dt, options)
    fallen.run_until(1.0)
    assert fallen.center_of_mass()[1] < start[1] - 4


def test_a_stiff_force_with_its_jacobian_is_stable_and_loses_energy_at_1_30_s():
    sim = free_cube(4, "implicit_euler", 1 / 30, implicit("cholmod"))
    sim.set_gravity([0.0, 0.0, 0.0])
    anchors = np.array(sim.model.rest_position).reshape(-1, 3) + [0.05, 0.0, 0.0]
    force = SpringsToAnchorsWithJacobian(anchors, 1e6)
    sim.add_force(force)
    assert force.check_jacobians(0.0, sim.state.x, sim.state.v) [0] < 1e-6

    def energy():
        return sim.kinetic_energy() + sim.elastic_energy() + force.energy(sim.state.x)

    e0 = last = energy()
    for _ in range(30):
        assert sim.step().ok
        e = energy()
        assert np.isfinite(e) and e <= last + 1e-12 * e0
        last = e
    assert last < 1e-6 * e0
    assert sim.run_until(sim.t + 0.1).notes == []


def test_the_same_force_without_its_jacobian_is_reported_as_explicit():
    sim = free_cube(3, "implicit_euler", 1 / 30, implicit("cholmod"))
    sim.add_force(SpringsToAnchors(np.array(sim.model.rest_position).reshape(-1, 3), 10.0))
    report = sim.run_until(0.1)
    assert report.notes == ["force 'springs_to_anchors' gives no Jacobian: implicit_euler "
                            "treats it explicitly within each step"]
    assert report.as_dict()["notes"] == report.notes
    assert sim.run_until(0.2).notes == []  # said once


def test_an_exception_in_a_force_stops_the_run_at_the_last_completed_step():
    class Failing(jelly.Force):
        def forces(self, t, x, v, f):
            if t > 0.0505:
                raise ValueError("the controller lost its input")

    sim = free_cube(3)
    handle = sim.add_force(Failing())
    with pytest.raises(ValueError, match="lost its input"):
        sim.run_until(1.0)
    reference = free_cube(3)
    reference.run_until(sim.t)
    assert sim.total_steps == reference.total_steps == 50
    assert np.array_equal(sim.state.x, reference.state.x)
    # Removed, the run goes on from there.
    assert sim.remove_force(handle) and not sim.remove_force(handle)
    assert sim.forces == []
    assert sim.run_until(0.1).ok


def test_a_jacobian_of_the_wrong_shape_is_an_input_error():
    class Bad(SpringsToAnchors):
        def jacobians(self, t, x, v):
            return scipy.sparse.identity(5), None

    sim = free_cube(3, "implicit_euler", 1 / 60, implicit("cholmod"))
    sim.add_force(Bad(np.zeros((27, 3)), 1.0))
    with pytest.raises(jelly.InputError, match=r"jacobians\(\)\[0\] shape"):
        sim.step()


def test_live_spring_edits_equal_a_simulator_built_with_them_bit_for_bit():
    edited = free_cube(3, "implicit_euler", 1 / 120)
    edited.run_until(0.25)
    # model=False: the state without the model's values of then (restored below into a
    # simulator of the edited model).
    snapshot = edited.snapshot(model=False)
    edited.set_spring_coefficients(0, "shear", 3000.0, 20.0)
    edited.run_until(0.5)
    fresh = jelly.Simulator(edited.model, snapshot.state, "implicit_euler",
                            jelly.IntegratorOptions(), edited.options)
    fresh.restore(snapshot)
    fresh.run_until(0.5)
    assert np.array_equal(edited.state.x, fresh.state.x)
    shear = np.asarray(edited.model.springs.type) == int(jelly.SpringType.shear)
    assert np.all(np.asarray(edited.model.springs.ks)[shear] == 3000.0)


def test_invalid_live_edits_raise_naming_the_field_and_change_nothing():
    sim = free_cube(3)
    ks = np.array(sim.model.springs.ks)
    with pytest.raises(jelly.InputError, match=r"bodies\[0\]\.springs\.bending\.ks = -1"):
        sim.set_spring_coefficients(0, "bending", -1.0, 2.0)
    with pytest.raises(jelly.InputError, match="spring type"):
        sim.set_spring_coefficients(0, "diagonal", 1.0, 2.0)
    with pytest.raises(jelly.InputError, match=r"bodies\[0\]\.particle_mass = 0"):
        sim.set_particle_mass("jelly", 0.0)
    with pytest.raises(jelly.InputError, match=r"integrator\.dt = -1"):
        sim.set_dt(-1.0)
    assert np.array_equal(sim.model.springs.ks, ks) and sim.options.dt == 1e-3


def test_switching_the_integrator_keeps_terrains_forces_pins_and_output(scenes):
    # The new user's report: rebuilding a simulator to switch integrator dropped the floor.
    sim = jelly.Simulator(jelly.load_scene(scenes / "drop_coulomb.json", ["cube.n=4"]))
    sim.add_force(AntiGravity(sim.model.mass, [0.0, 0.0, 0.0]))
    sim.set_pin(0)
    frames = []
    sim.run_until(0.2, callback=lambda s: frames.append(s.t))
    sim.set_integrator("implicit_euler")
    sim.set_dt(1 / 60)
    report = sim.run_until(3.0, callback=lambda s: frames.append(s.t))
    assert report.ok, report.brief()
    assert sim.integrator.name == "implicit_euler"
    assert len(sim.terrains) == 1 and len(sim.forces) == 1
    assert np.array_equal(sim.state.x[0], np.asarray(sim.model.rest_position).reshape(-1, 3)[0])
    assert len(frames) > 100
    assert sim.state.x[:, 1].min() > -0.05  # the floor (y = 0) held


def test_a_pin_on_a_circle_stays_on_it():
    sim = free_cube(3)
    anchor = np.array(sim.model.rest_position).reshape(-1, 3)[0]
    sim.set_pin(0, path={"kind": "circle", "center": [0.3, 0.0, 0.4], "axis": [0, 1, 0],
                         "period": 0.7})
    for _ in range(500):
        assert sim.step().ok
        assert abs(np.linalg.norm(sim.state.x[0] - (anchor + [0.3, 0.0, 0.4])) - 0.5) < 1e-12
    with pytest.raises(jelly.InputError, match=r"path\.period = 0"):
        sim.set_pin(0, path={"kind": "circle", "center": [0.3, 0, 0], "period": 0})


def test_a_snapshot_after_live_edits_restores_them_also_through_pickle():
    import pickle
    sim = free_cube(3, "implicit_euler", 1 / 60)
    sim.run_until(0.2)
    sim.set_spring_coefficients(0, "structural", 200.0, 1.0)
    sim.set_pin(0)
    sim.set_pin_target(0, sim.state.x[0], [0.0, 1.0, 0.0])
    snapshot = pickle.loads(pickle.dumps(sim.snapshot()))
    sim.run_until(0.5)
    fresh = free_cube(3, "implicit_euler", 1 / 60)  # the model as built, unedited
    fresh.restore(snapshot)
    fresh.run_until(0.5)
    assert np.array_equal(fresh.state.x, sim.state.x)
    assert np.array_equal(fresh.model.springs.ks, sim.model.springs.ks)


def test_the_pin_controller_example_carries_the_jelly_to_its_goal():
    import os, pathlib, subprocess, sys
    script = pathlib.Path(os.environ.get("JELLY_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
    done = subprocess.run([sys.executable, str(script / "examples/python/pin_controller.py"),
                           "--seconds", "6"], capture_output=True, text=True, check=True)
    miss = float(done.stdout.split("the centre is ")[1].split()[0])
    assert miss < 0.01, done.stdout
