"""Bodies from Python: the scene's "bodies" list, the model's bodies (particle and spring ranges,
render surfaces as NumPy, groups), pins and external forces, body and terrain kinds, checked
against geometry (enclosed volumes, spheres) and mechanics (free fall, a constant force, pins
held exactly)."""

import json

import numpy as np
import pytest

import jelly

G = np.array([0.0, -9.8, 0.0])


def scene_of(bodies, terrains=(), gravity=(0, -9.8, 0), integrator="rk4", dt=1e-3):
    return jelly.Scene({"bodies": list(bodies), "gravity": list(gravity),
                        "terrains": list(terrains),
                        "integrator": {"name": integrator, "dt": dt}, "duration": 1})


def enclosed_volume(vertices, triangles):
    """Volume inside a closed triangle surface (divergence theorem); > 0 when the triangles are
    counter-clockwise seen from outside."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def body_com(model, body, state):
    m = model.mass[body.first_particle:body.first_particle + body.num_particles]
    return (m[:, None] * body.x(state)).sum(axis=0) / m.sum()


def test_body_kinds_are_listed_and_each_builds_its_body():
    kinds = jelly.body_kinds()
    assert {"cube", "box", "cloth"} <= set(kinds)
    assert all(isinstance(d, str) and d for d in kinds.values())
    for kind in ("cube", "box", "cloth"):  # the mesh kinds need a file
        sim = jelly.Simulator(scene_of([{"kind": kind, "name": "b_" + kind}]))
        (body,) = sim.model.bodies
        assert (body.kind, body.name) == (kind, "b_" + kind)
        assert body.num_particles == sim.model.num_particles
    assert {"plane", "slope", "elevator", "sphere"} <= set(jelly.terrain_kinds())
    assert set(jelly.contact_models()) == {"coulomb", "seed", "seed_framework"}
    assert jelly.cube_particle_count(10) == 1000 and jelly.cube_spring_count(10) == 12876


def test_bodies_cover_the_model_in_order(scenes):
    scene = jelly.load_scene(scenes / "two_jellies.json")
    assert [b.name for b in scene.bodies] == ["soft", "stiff"]  # the scene's list
    model = jelly.Simulator(scene).model
    soft, stiff = model.bodies
    assert (soft.particles, stiff.particles) == (range(0, 216), range(216, 432))
    assert soft.springs.stop == stiff.springs.start and stiff.springs.stop == model.num_springs
    assert soft.num_springs == jelly.cube_spring_count(6)
    # Each body's springs join its own particles.
    a, b = model.springs.a[stiff.first_spring:], model.springs.b[stiff.first_spring:]
    assert a.min() >= 216 and b.min() >= 216
    assert model.body("stiff").name == "stiff" and model.body_of(300).name == "stiff"
    assert stiff.contains(431) and not stiff.contains(215)
    with pytest.raises(KeyError, match="its bodies: soft, stiff"):
        model.body("medium")
    with pytest.raises(jelly.InputError, match="particle = 432 is invalid"):
        model.body_of(432)


@pytest.mark.parametrize("spec, volume", [
    ({"kind": "cube", "n": 5, "edge_length": 1.5, "origin": [0, 2, 0]}, 1.5**3),
    ({"kind": "box", "nx": 4, "ny": 3, "nz": 5, "size": [2, 0.5, 1.2],
      "rotation_degrees": [10, 20, 30]}, 2 * 0.5 * 1.2),
])
def test_closed_surfaces_enclose_the_body_volume(spec, volume):
    sim = jelly.Simulator(scene_of([dict(spec, name="b")]))
    body = sim.model.bodies[0]
    triangles = body.surface.triangles
    assert triangles.dtype == np.int32 and triangles.shape == (body.surface.num_triangles, 3)
    assert not triangles.flags.writeable
    vertices = body.surface_vertices(sim.state)
    assert vertices.shape == (body.surface.num_vertices, 3)
    assert enclosed_volume(vertices, triangles) == pytest.approx(volume, rel=1e-12)


def test_thickness_defaults_to_the_cloths_radius_and_is_kept_from_terrains():
    cloth = {"kind": "cloth", "name": "c", "nu": 5, "nv": 5, "size_u": 1, "size_v": 1,
             "position": [0, 0.3, 0], "particle_mass": 0.01}
    cube = {"kind": "cube", "name": "k", "n": 3, "edge_length": 0.5, "origin": [3, 0.1, 0]}
    floor = {"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
             "contact": {"model": "coulomb", "restitution": 0}}
    sim = jelly.Simulator(scene_of([cloth, cube], [floor], integrator="implicit_euler",
                                   dt=1 / 60))
    c, k = sim.model.bodies
    assert c.thickness == c.radius == pytest.approx(0.125)
    assert k.thickness == 0
    import pickle
    assert pickle.loads(pickle.dumps(sim.model)).bodies[0].thickness == c.thickness
    sim.run_until(1.0)
    assert c.x(sim.state)[:, 1] == pytest.approx(c.thickness, abs=1e-6)
    set_scene = scene_of([dict(cloth, thickness=0.02)])
    assert jelly.Simulator(set_scene).model.bodies[0].thickness == 0.02
    with pytest.raises(jelly.InputError, match=r"bodies\[0\]\.thickness = -1"):
        jelly.Simulator(scene_of([dict(cloth, thickness=-1)]))


def test_color_is_the_scenes_and_kept_by_pickling():
    cube = {"kind": "cube", "n": 3, "edge_length": 0.5, "origin": [0, 1, 0]}
    sim = jelly.Simulator(scene_of([dict(cube, name="plain"),
                                    dict(cube, name="green", origin=[2, 1, 0],
                                         color=[0.1, 0.8, 0.2])]))
    plain, green = sim.model.bodies
    assert plain.color is None
    assert list(green.color) == [0.1, 0.8, 0.2]
    import pickle
    assert list(pickle.loads(pickle.dumps(sim.model)).bodies[1].color) == [0.1, 0.8, 0.2]
    with pytest.raises(jelly.InputError, match=r"bodies\[0\]\.color"):
        jelly.Simulator(scene_of([dict(cube, name="bad", color=[0, 2, 0])]))


def test_cloth_surface_is_its_flat_sheet():
    sim = jelly.Simulator(scene_of([{"kind": "cloth", "name": "c", "nu": 6, "nv": 4,
                                     "size_u": 2, "size_v": 1.5, "position": [0, 3, 0]}]))
    body = sim.model.bodies[0]
    v = body.surface_vertices(sim.state)
    t = body.surface.triangles
    normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]) / 2
    assert np.allclose(v[:, 1], 3.0)
    assert np.allclose(normals[:, [0, 2]], 0)
    # One side of the sheet, or both: the area seen from +y is the sheet's.
    assert np.abs(normals[:, 1][normals[:, 1] > 0]).sum() == pytest.approx(2 * 1.5, rel=1e-12)
    assert set(body.groups) >= {"corner_00", "corner_10", "corner_01", "corner_11"}
    corners = np.concatenate([body.groups[k] for k in ("corner_00", "corner_10",
                                                       "corner_01", "corner_11")])
    x = sim.state.x[corners]
    assert sorted(np.round(x[:, 0], 12)) == [-1, -1, 1, 1]


def test_surface_vertices_are_the_weighted_particles_and_views_follow_the_state(scenes):
    scene = jelly.load_scene(scenes / "two_jellies.json", {"duration": 0.2})
    sim = jelly.Simulator(scene)
    stiff = sim.model.body("stiff")
    x_view = stiff.x(sim.state)
    assert np.shares_memory(x_view, sim.state.x) and not x_view.flags.writeable
    before = x_view.copy()
    assert sim.run_until(0.2).ok
    assert not np.array_equal(x_view, before)  # the same memory, stepped
    assert np.array_equal(x_view, sim.state.x[stiff.particles.start:stiff.particles.stop])
    s = stiff.surface
    x = sim.state.x
    expected = np.add.reduceat(s.weights[:, None] * x[s.particles], s.offsets[:-1])
    assert np.allclose(stiff.surface_vertices(sim.state), expected, rtol=0, atol=1e-14)
    assert np.array_equal(stiff.surface_vertices(sim.state), s.vertices(np.array(x)))
    with pytest.raises(jelly.InputError, match="x.size"):
        s.vertices(np.zeros((10, 3)))


def test_each_body_falls_freely_at_g():
    # Two cubes without terrain: each body's centre of mass follows x0 + g t^2 / 2 and each
    # body's momentum is M g t (its springs are internal forces; RK4 is exact for this
    # quadratic).
    sim = jelly.Simulator(scene_of([
        {"kind": "cube", "name": "a", "n": 3, "edge_length": 1, "origin": [0, 5, 0]},
        {"kind": "box", "name": "b", "nx": 3, "ny": 2, "nz": 4, "size": [1, 0.5, 2],
         "position": [3, 5, 0], "particle_mass": 0.5}]))
    model = sim.model
    x0 = [body_com(model, b, sim.state) for b in model.bodies]
    t = 0.5
    assert sim.run_until(t).ok
    for body, c0 in zip(model.bodies, x0):
        assert body_com(model, body, sim.state) == pytest.approx(c0 + G * t**2 / 2, abs=1e-9)
        m = model.mass[body.particles.start:body.particles.stop]
        p = (m[:, None] * body.v(sim.state)).sum(axis=0)
        assert p == pytest.approx(m.sum() * G * t, abs=1e-9)


def test_a_constant_external_force_accelerates_its_body_by_f_over_m():
    force = [2.0, 0.0, -1.0]
    sim = jelly.Simulator(scene_of(
        [{"kind": "cube", "name": "a", "n": 3, "edge_length": 1, "particle_mass": 0.25,
          "forces": [{"kind": "constant", "force": force}]}], gravity=(0, 0, 0)))
    (f,) = sim.model.external_forces
    assert f.kind == "constant" and list(f.vector) == force and len(f.particles) == 27
    assert f.start == 0 and f.end == float("inf")
    body = sim.model.bodies[0]
    c0 = body_com(sim.model, body, sim.state)
    t = 0.4
    assert sim.run_until(t).ok
    m = 27 * 0.25
    assert body_com(sim.model, body, sim.state) == pytest.approx(
        c0 + np.array(force) / m * t**2 / 2, abs=1e-9)


def test_pins_hold_their_particles_on_their_paths(scenes):
    # A driven pin (oscillation of 0.4 m at 0.5 Hz) under RK4 and fixed cloth corners under
    # implicit Euler at 1/60 s: the pinned particles are exactly where their paths say.
    sim = jelly.Simulator(jelly.load_scene(scenes / "pinned_jelly.json"))
    pins = sim.model.pins
    assert len(pins) >= 1 and not pins.all_fixed
    assert np.array_equal(pins.anchors, sim.state.x[pins.particles])
    assert sim.run_until(0.5).ok
    assert np.allclose(sim.state.x[pins.particles], pins.positions(sim.t), rtol=0, atol=1e-12)
    assert np.allclose(pins.positions(0.5) - pins.anchors, [0, 0.4, 0], atol=1e-12)

    sim = jelly.Simulator(jelly.load_scene(scenes / "hanging_cloth.json"))
    pins = sim.model.pins
    cloth = sim.model.body("cloth")
    assert pins.all_fixed and sorted(pins.particles) == sorted(
        np.concatenate([cloth.groups["corner_00"], cloth.groups["corner_10"]]))
    assert sim.run_until(1.0).ok
    assert np.array_equal(sim.state.x[pins.particles], pins.anchors)
    assert sim.state.x[:, 1].min() < pins.anchors[:, 1].min() - 0.5  # the rest hangs down


def test_terrains_of_every_kind_from_their_specs():
    sphere = jelly.make_terrain({"kind": "sphere", "center": [1, 2, 3], "radius": 1.5,
                                 "contact": {"restitution": 0.2}})
    assert sphere.kind == "sphere" and sphere.contact.restitution == 0.2
    p = np.array([1.0, 6.0, 3.0])
    assert sphere.signed_distance(p, 0) == pytest.approx(4 - 1.5)
    assert sphere.normal(p, 0) == pytest.approx([0, 1, 0])
    vertices, triangles = sphere.render_mesh()
    pose = sphere.pose(0)
    world = vertices @ pose[:3, :3].T + pose[:3, 3]
    assert np.allclose(np.linalg.norm(world - [1, 2, 3], axis=1), 1.5)
    assert enclosed_volume(world - [1, 2, 3], triangles) > 0
    with pytest.raises(jelly.InputError, match=r"terrain\.radius = -1 is invalid"):
        jelly.make_terrain({"kind": "sphere", "radius": -1})
    with pytest.raises(jelly.InputError, match=r"terrain\.kind"):
        jelly.make_terrain('{"kind": "torus"}')


def test_a_terrain_added_from_its_spec_equals_the_scene_s():
    cube = {"kind": "cube", "name": "a", "n": 3, "edge_length": 1, "origin": [-0.5, 1.6, -0.5]}
    sphere = {"kind": "sphere", "center": [0.2, 0, 0], "radius": 1,
              "contact": {"model": "coulomb", "restitution": 0.5}}
    from_scene = jelly.Simulator(scene_of([cube], terrains=[sphere]))
    added = jelly.Simulator(scene_of([cube]))
    added.add_terrain(json.dumps(sphere))
    free = jelly.Simulator(scene_of([cube]))
    for sim in (from_scene, added, free):
        assert sim.run_until(0.6).ok
    assert np.array_equal(from_scene.state.x, added.state.x)
    # It reached the sphere (0.6 m below it, at about 0.35 s): free fall went further down.
    assert from_scene.state.x[:, 1].min() > free.state.x[:, 1].min() + 0.1
    with pytest.raises(jelly.InputError, match="a Plane, an Elevator, or the spec"):
        added.add_terrain(added.terrains[0])


def test_an_obstacle_moved_between_steps_is_replaced_in_place():
    # A sphere moved from far away to under the cube mid-run: the cube lands on it from then on,
    # the floor (terrains[1]) keeps its index, and a bad index or spec changes nothing.
    cube = {"kind": "cube", "name": "a", "n": 3, "edge_length": 1, "origin": [-0.5, 1.6, -0.5]}
    far = {"kind": "sphere", "center": [20, 0, 0], "radius": 1}
    floor = {"kind": "plane", "point": [0, -3, 0], "normal": [0, 1, 0]}
    sim = jelly.Simulator(scene_of([cube], terrains=[far, floor]))
    assert sim.run_until(0.1).ok
    sim.replace_terrain(0, dict(far, center=[0.2, 0, 0]))
    assert sim.terrains[0].pose(0)[0, 3] == pytest.approx(0.2)
    assert sim.terrains[1].kind == "plane"
    with pytest.raises(jelly.InputError, match=r"terrain index = 2 is invalid"):
        sim.replace_terrain(2, far)
    with pytest.raises(jelly.InputError, match=r"terrain\.radius = -1 is invalid"):
        sim.replace_terrain(0, dict(far, radius=-1))
    assert sim.terrains[0].pose(0)[0, 3] == pytest.approx(0.2)
    assert sim.run_until(0.6).ok
    free = jelly.Simulator(scene_of([cube], terrains=[far, floor]))
    assert free.run_until(0.6).ok
    assert sim.state.x[:, 1].min() > free.state.x[:, 1].min() + 0.1


def test_a_model_of_several_bodies_from_a_scene_runs_in_a_simulator_built_in_code():
    scene = scene_of([
        {"kind": "cloth", "name": "sheet", "nu": 4, "nv": 4, "position": [0, 2, 0],
         "pins": [{"group": "corner_00"}]},
        {"kind": "box", "name": "brick", "nx": 2, "ny": 2, "nz": 2, "position": [3, 2, 0]}])
    model = jelly.make_model(scene)
    assert [b.kind for b in model.bodies] == ["cloth", "box"] and len(model.pins) == 1
    sim = jelly.Simulator(model, integrator="rk4")
    assert sim.report is None
    report = sim.run_until(0.3)
    assert sim.report.status == report.status == "completed" and sim.report.steps == 300
    brick = sim.model.body("brick")
    com = body_com(sim.model, brick, sim.state)
    assert com[1] == pytest.approx(2 + G[1] * 0.3**2 / 2, abs=1e-9)
    assert np.array_equal(sim.state.x[model.pins.particles], model.pins.anchors)


def test_two_free_bodies_collide_with_momentum_kept():
    # Two cubes in zero gravity thrown at each other (1 m/s each, offset by 0.3 m): the body
    # contact's equal and opposite impulses keep the linear momentum (0) exactly; without
    # friction, under symplectic Euler (exact for central forces), the angular momentum too.
    scene = scene_of([
        {"kind": "cube", "name": "a", "n": 3, "edge_length": 1, "origin": [-1.5, 0, 0]},
        {"kind": "cube", "name": "b", "n": 3, "edge_length": 1, "origin": [0.5, 0.3, 0]}],
        gravity=(0, 0, 0), integrator="symplectic_euler")
    sim = jelly.Simulator(scene)
    assert sim.body_contact["enabled"] and sim.body_contact["friction"] == 0.5
    sim.set_body_contact({"friction": 0, "static_friction": 0, "restitution": 0.5})
    assert sim.body_contact["friction"] == 0 and sim.body_contact["restitution"] == 0.5
    with pytest.raises(jelly.InputError, match=r"body_contact\.restitution = 2 is invalid"):
        sim.set_body_contact({"restitution": 2})
    a, b = sim.model.bodies
    v = np.zeros((sim.model.num_particles, 3))
    v[a.particles.start:a.particles.stop, 0] = 1
    v[b.particles.start:b.particles.stop, 0] = -1
    sim.state.v = v
    L0 = sim.angular_momentum()
    most = []

    def frame(s):
        pairs = s.body_contact_pairs
        assert pairs.shape[1:] == (2,)
        assert all(a.contains(i) and b.contains(j) for i, j in pairs)  # one of each body
        most.append(len(pairs))

    assert sim.run_until(1.0, callback=frame).ok
    assert max(most) > 0 and len(sim.body_contact_pairs) == 0  # they touched, then parted
    assert np.abs(sim.linear_momentum()).max() < 1e-12
    assert np.abs(sim.angular_momentum() - L0).max() < 1e-12 * np.abs(L0).max()
    assert a.v(sim.state)[:, 0].mean() < 0 < b.v(sim.state)[:, 0].mean()  # bounced back


def test_body_x_and_v_of_something_not_a_state_is_a_type_error_naming_it(scenes):
    """An array of positions instead of a State: a TypeError naming what was given and what is
    expected, not pybind11's "Unable to cast"."""
    sim = jelly.Simulator(jelly.load_scene(scenes / "seed_slope.json", {"cube.n": 3}))
    body = sim.model.bodies[0]
    for method in (body.x, body.v):
        with pytest.raises(TypeError, match=r"must be a jelly\.State .*not ndarray"):
            method(np.zeros((27, 3)))
    assert body.x(sim.state).shape == (27, 3)
