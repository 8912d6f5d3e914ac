"""jelly.gradient (the discrete adjoints of implicit_euler and projective_dynamics,
docs/gradients.md) against central finite differences of the loss, and its messages for bad paths
and shapes."""

import warnings

import numpy as np
import pytest

import jelly

STEPS = 10
DT = 1 / 60


def cloth_scene(overrides=None, integrator=None):
    scene = {
        "bodies": [{
            "kind": "cloth", "name": "cloth", "nu": 5, "nv": 5, "size_u": 1, "size_v": 1,
            "position": [0, 2, 0], "particle_mass": 0.05,
            "springs": {"structural": {"ks": 300, "kd": 2}, "shear": {"ks": 150, "kd": 1},
                        "bending": {"ks": 40, "kd": 0.5}},
            "velocity": [0.3, 0, -0.2],
            "pins": [{"group": "corner_00"}, {"group": "corner_10"}]}],
        "gravity": [0, -9.8, 0],
        "terrains": [],
        "integrator": integrator or {"name": "implicit_euler", "dt": DT},
        "duration": STEPS * DT,
    }
    return jelly.Scene(scene, overrides or {})


WEIGHTS = np.random.default_rng(3).uniform(-1, 1, (25, 3))


def loss(x, v):
    return float((WEIGHTS * x).sum() + 0.05 * (v * v).sum()), WEIGHTS.copy(), 0.1 * v


def driven_pin(scene):
    sim = jelly.Simulator(scene)
    return int(sim.model.pins.particles[1])


def targets(scene):
    sim = jelly.Simulator(scene)
    start = np.array(sim.state.x)[driven_pin(scene)]
    k = np.arange(1, STEPS + 1)[:, None]
    return (start + 0.05 * np.hstack([np.sin(0.3 * k), 1 - np.cos(0.3 * k), 0.1 * k]))[:, None, :]


def value(scene, pin_targets):
    pin = driven_pin(scene)
    return jelly.gradient(scene, STEPS * DT, loss, [], pins=[pin], pin_targets=pin_targets)[0]


def central(scene_of, pin_targets_of, eps):
    return (value(scene_of(eps), pin_targets_of(eps)) -
            value(scene_of(-eps), pin_targets_of(-eps))) / (2 * eps)


def test_every_kind_agrees_with_finite_differences():
    scene = cloth_scene()
    pin = driven_pin(scene)
    wrt = ["bodies[0].springs.structural.ks", "bodies[0].springs.shear.kd", "gravity",
           "bodies[0].mass", "bodies[0].velocity", "pin_targets"]
    base = targets(scene)
    L, grads = jelly.gradient(scene, STEPS * DT, loss, wrt, pins=[pin], pin_targets=base)
    assert np.isclose(L, value(scene, base), rtol=1e-14)
    L2, again = jelly.gradient(scene, STEPS * DT, loss, wrt, pins=[pin], pin_targets=base,
                               checkpoint_every=3)
    assert L2 == L and all(np.array_equal(again[p], grads[p]) for p in wrt)
    assert grads["gravity"].shape == (3,)
    assert grads["pin_targets"].shape == (STEPS, 1, 3)
    fixed = lambda e: base  # noqa: E731
    checks = {
        "bodies[0].springs.structural.ks":
            central(lambda e: cloth_scene({"bodies[0].springs.structural.ks": 300 + e}), fixed,
                    1e-4),
        "bodies[0].springs.shear.kd":
            central(lambda e: cloth_scene({"bodies[0].springs.shear.kd": 1 + e}), fixed, 1e-6),
        "bodies[0].mass":
            central(lambda e: cloth_scene({"bodies[0].particle_mass": 0.05 + e}), fixed, 1e-8),
    }
    for path, fd in checks.items():
        assert abs(float(grads[path]) - fd) <= 1e-5 * abs(fd), (path, grads[path], fd)
    fd_gravity = central(lambda e: cloth_scene({"gravity": [0, -9.8 + e, 0]}), fixed, 1e-6)
    assert abs(grads["gravity"][1] - fd_gravity) <= 1e-5 * abs(fd_gravity)
    fd_velocity = central(lambda e: cloth_scene({"bodies[0].velocity": [0.3 + e, 0, -0.2]}),
                          fixed, 1e-6)
    assert abs(grads["bodies[0].velocity"][0] - fd_velocity) <= 1e-5 * abs(fd_velocity)
    direction = np.random.default_rng(5).uniform(-1, 1, base.shape)
    fd_targets = central(lambda e: scene, lambda e: base + e * direction, 1e-6)
    adjoint = float((grads["pin_targets"] * direction).sum())
    assert abs(adjoint - fd_targets) <= 1e-5 * abs(fd_targets)


def test_bad_paths_and_shapes_are_named():
    scene = cloth_scene()
    with pytest.raises(jelly.InputError, match="wrt: 'bodies\\[0\\].springs.twist.ks'"):
        jelly.gradient(scene, STEPS * DT, loss, ["bodies[0].springs.twist.ks"])
    with pytest.raises(jelly.InputError, match="pin_targets"):
        jelly.gradient(scene, STEPS * DT, loss, [], pins=[0], pin_targets=np.zeros((2, 1, 3)))
    with pytest.raises(jelly.InputError, match="dL/dx"):
        jelly.gradient(scene, STEPS * DT, lambda x, v: (0.0, np.zeros((3, 3)), v), [])
    with pytest.raises(jelly.InputError, match="duration"):
        jelly.gradient(scene, 0.001, loss, [])
    rk4 = cloth_scene({"integrator.name": "rk4", "integrator.dt": 0.001})
    with pytest.raises(jelly.InputError, match="implicit_euler"):
        jelly.gradient(rk4, 0.01, loss, ["gravity"])


def forced_scene(push=(0.2, 0.1, -0.3), air=(1.0, 0.2, 2.0), drag=0.02, gust=0.4):
    scene = {
        "bodies": [{
            "kind": "cloth", "name": "cloth", "nu": 5, "nv": 5, "size_u": 1, "size_v": 1,
            "position": [0, 2, 0], "particle_mass": 0.05,
            "springs": {"structural": {"ks": 300, "kd": 2}, "shear": {"ks": 150, "kd": 1},
                        "bending": {"ks": 40, "kd": 0.5}},
            "velocity": [0.3, 0, -0.2],
            "pins": [{"group": "corner_00"}, {"group": "corner_10"}],
            "forces": [{"kind": "constant", "force": list(push)},
                       {"kind": "wind", "velocity": list(air), "drag": drag, "gust": gust,
                        "gust_frequency": 2}]}],
        "gravity": [0, -9.8, 0],
        "terrains": [],
        "integrator": {"name": "implicit_euler", "dt": DT},
        "duration": STEPS * DT,
    }
    return jelly.Scene(scene, {})


def test_external_force_parameters_agree_with_finite_differences():
    wrt = ["bodies[0].forces[0].force", "bodies[0].forces[0].gust", "bodies[0].forces[1].velocity",
           "bodies[0].forces[1].drag", "bodies[0].forces[1].gust"]
    L, grads = jelly.gradient(forced_scene(), STEPS * DT, loss, wrt)
    assert grads["bodies[0].forces[0].force"].shape == (3,)

    def fd(make, eps):
        return (jelly.gradient(make(eps), STEPS * DT, loss, [])[0] -
                jelly.gradient(make(-eps), STEPS * DT, loss, [])[0]) / (2 * eps)

    for d in range(3):
        unit = np.eye(3)[d]
        push = fd(lambda e: forced_scene(push=np.array([0.2, 0.1, -0.3]) + e * unit), 1e-6)
        assert abs(grads["bodies[0].forces[0].force"][d] - push) <= 1e-5 * abs(push), (d, push)
        air = fd(lambda e: forced_scene(air=np.array([1.0, 0.2, 2.0]) + e * unit), 1e-6)
        assert abs(grads["bodies[0].forces[1].velocity"][d] - air) <= 1e-5 * abs(air), (d, air)
    drag = fd(lambda e: forced_scene(drag=0.02 + e), 1e-7)
    assert abs(float(grads["bodies[0].forces[1].drag"]) - drag) <= 1e-5 * abs(drag)
    gust = fd(lambda e: forced_scene(gust=0.4 + e), 1e-6)
    assert abs(float(grads["bodies[0].forces[1].gust"]) - gust) <= 1e-5 * abs(gust)
    # The constant force has no gust: its gradient is that of a (zero) amplitude, still defined.
    assert np.isfinite(float(grads["bodies[0].forces[0].gust"]))
    with pytest.raises(jelly.InputError, match="for a constant force, force, gust"):
        jelly.gradient(forced_scene(), STEPS * DT, loss, ["bodies[0].forces[0].drag"])
    with pytest.raises(jelly.InputError, match="a force index below 2"):
        jelly.gradient(forced_scene(), STEPS * DT, loss, ["bodies[0].forces[2].gust"])


def stacked_scene(overrides=None):
    """A cube landing on another that rests on a sticky floor, moving sideways: frictionless
    contact between the bodies inside the solve at every step."""
    def cube(name, y, mass, ks, velocity):
        return {"kind": "cube", "name": name, "n": 3, "edge_length": 0.3,
                "origin": [0, y, 0], "particle_mass": mass, "velocity": velocity,
                "springs": {t: {"ks": ks, "kd": 0.02 * ks} for t in
                            ("structural", "shear", "bending")}}
    scene = {
        "bodies": [cube("lower", 0.002, 0.3, 800, [0, 0, 0]),
                   cube("upper", 0.302 + 0.1505, 0.1, 300, [0.1, -0.05, 0])],
        "gravity": [0, -9.8, 0],
        "terrains": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                      "contact": {"model": "coulomb", "restitution": 0, "friction": 3,
                                  "static_friction": 3}}],
        "body_contact": {"restitution": 0, "friction": 0, "static_friction": 0},
        "integrator": {"name": "implicit_euler", "dt": 0.01},
        "duration": 0.1,
    }
    return jelly.Scene(scene, overrides or {})


STACK_WEIGHTS = np.random.default_rng(4).uniform(-1, 1, (54, 3))


def stack_loss(x, v):
    return float((STACK_WEIGHTS * x).sum() + 0.05 * (v * v).sum()), STACK_WEIGHTS.copy(), 0.1 * v


def test_contact_between_bodies_agrees_with_finite_differences():
    wrt = ["bodies[1].springs.structural.ks", "bodies[0].mass", "bodies[1].velocity"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing held: frictionless pairs, no restitution
        L, grads = jelly.gradient(stacked_scene(), 0.1, stack_loss, wrt)

    def fd(overrides_of, eps):
        plus = jelly.gradient(stacked_scene(overrides_of(eps)), 0.1, stack_loss, [])[0]
        minus = jelly.gradient(stacked_scene(overrides_of(-eps)), 0.1, stack_loss, [])[0]
        return (plus - minus) / (2 * eps)

    checks = {
        "bodies[1].springs.structural.ks":
            fd(lambda e: {"bodies[1].springs.structural.ks": 300 + e}, 1e-4),
        "bodies[0].mass": fd(lambda e: {"bodies[0].particle_mass": 0.3 + e}, 1e-7),
    }
    for path, expected in checks.items():
        assert abs(float(grads[path]) - expected) <= 1e-5 * abs(expected), \
            (path, grads[path], expected)
    expected = fd(lambda e: {"bodies[1].velocity": [0.1 + e, -0.05, 0]}, 1e-7)
    assert abs(grads["bodies[1].velocity"][0] - expected) <= 1e-5 * abs(expected)


# projective_dynamics run to convergence (the adjoint is of its fixed point).
PD = {"name": "projective_dynamics", "dt": DT, "options": {"iterations": 600}}


def test_projective_dynamics_agrees_with_finite_differences():
    scene = cloth_scene(integrator=PD)
    pin = driven_pin(scene)
    base = targets(scene)
    wrt = ["bodies[0].springs.structural.ks", "bodies[0].mass", "pin_targets"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # converged: no warning
        L, grads = jelly.gradient(scene, STEPS * DT, loss, wrt, pins=[pin], pin_targets=base)
    assert np.isclose(L, value(scene, base), rtol=1e-14)
    fixed = lambda e: base  # noqa: E731
    fd_ks = central(lambda e: cloth_scene({"bodies[0].springs.structural.ks": 300 + e}, PD),
                    fixed, 1e-4)
    assert abs(float(grads[wrt[0]]) - fd_ks) <= 1e-5 * abs(fd_ks)
    fd_mass = central(lambda e: cloth_scene({"bodies[0].particle_mass": 0.05 + e}, PD), fixed,
                      1e-8)
    assert abs(float(grads[wrt[1]]) - fd_mass) <= 1e-5 * abs(fd_mass)
    direction = np.random.default_rng(5).uniform(-1, 1, base.shape)
    fd_targets = central(lambda e: scene, lambda e: base + e * direction, 1e-6)
    adjoint = float((grads["pin_targets"] * direction).sum())
    assert abs(adjoint - fd_targets) <= 1e-5 * abs(fd_targets)
    # A few iterations stop short of the fixed point: the gradient says so.
    short = cloth_scene(integrator={"name": "projective_dynamics", "dt": DT,
                                    "options": {"iterations": 3}})
    with pytest.warns(UserWarning, match="converged steps"):
        jelly.gradient(short, STEPS * DT, loss, wrt[:1], pins=[pin], pin_targets=base)
