"""The module imports, every public name is in the .pyi stub (and the stub names nothing that
is not there), and everything public has a docstring."""

import ast
import inspect
import pathlib
import re

import jelly

STUB = pathlib.Path(jelly.__file__).with_name("__init__.pyi")


def stub_names():
    """Top-level names of the stub, and the member names of each class in it."""
    tree = ast.parse(STUB.read_text())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
        if isinstance(node, ast.ClassDef):
            body = set()
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.ClassDef)):
                    body.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    body.add(item.target.id)
                elif isinstance(item, ast.Assign):
                    body.update(t.id for t in item.targets if isinstance(t, ast.Name))
            members[node.name] = body
    return names, members


def public(names):
    return {n for n in names if not n.startswith("_")}


def test_imports_from_the_build_tree():
    assert jelly.__version__.count(".") == 2
    assert issubclass(jelly.InputError, ValueError)
    assert pathlib.Path(jelly.__file__).parent == pathlib.Path(jelly._jelly.__file__).parent


def test_every_public_name_is_in_the_stub():
    names, members = stub_names()
    runtime = set(jelly.__all__)
    assert runtime == public(dir(jelly)) - {"annotations"}
    assert runtime - names == set(), "missing from __init__.pyi"
    assert public(names) - runtime == set(), "in __init__.pyi but not in the module"
    for name in sorted(runtime):
        obj = getattr(jelly, name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            missing = public(vars(obj)) - members[name]
            assert missing == set(), f"{name}: members missing from __init__.pyi"
            extra = public(members[name]) - public(dir(obj))
            assert extra == set(), f"{name}: members in __init__.pyi but not in the class"


def stub_annotations():
    """{class name: {attribute: annotation text}} of the stub's classes."""
    tree = ast.parse(STUB.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            out[node.name] = {item.target.id: ast.unparse(item.annotation) for item in node.body
                              if isinstance(item, ast.AnnAssign)
                              and isinstance(item.target, ast.Name)}
    return out


def test_option_classes_in_the_stub_are_their_field_tables():
    # The option classes' properties come from the C++ field tables (python/src/fields.hpp), which
    # list them as _fields: (name, Python type). The stub must annotate exactly those fields with
    # those types, and a default instance must hold values of those types.
    annotations = stub_annotations()
    tables = {name: getattr(jelly, name)._fields for name in jelly.__all__
              if inspect.isclass(getattr(jelly, name)) and hasattr(getattr(jelly, name), "_fields")}
    assert {"ImplicitEulerOptions", "ArkodeOptions", "ProjectiveDynamicsOptions", "XpbdOptions",
            "VbdOptions", "ContactParams", "DivergenceGuard", "SimulatorOptions", "ElevatorSpec",
            "SpringCoefficients"} <= set(tables)
    runtime = {"_FloatArray": "ndarray"}  # the stub's alias of a NumPy array
    for name, fields in sorted(tables.items()):
        stub = annotations[name]
        assert {f: stub.get(f) for f, _ in fields} == dict(fields), (
            f"{name}: __init__.pyi disagrees with its table")
        # Members beyond the table's (not scene keys, e.g. DivergenceGuard.max_energy) are
        # properties bound by hand: none of them may shadow a field.
        extra = set(stub) - {f for f, _ in fields}
        assert all(isinstance(getattr(getattr(jelly, name), e, None), property) for e in extra), (
            f"{name}: {sorted(extra)}")
        obj = getattr(jelly, name)()
        for field, type_name in fields:
            assert type(getattr(obj, field)).__name__ == runtime.get(type_name, type_name), (
                f"{name}.{field}")


def test_stub_attribute_types_match_the_module():
    # Every class of the stub that takes no constructor arguments: each attribute the stub
    # annotates as int, float, bool or str holds a value of that type in a default instance.
    simple = {"int": int, "float": float, "bool": bool, "str": str}
    checked = 0
    for name, attributes in sorted(stub_annotations().items()):
        cls = getattr(jelly, name, None)
        if not inspect.isclass(cls) or issubclass(cls, BaseException):
            continue
        try:
            obj = cls()
        except TypeError:
            continue
        for attribute, annotation in attributes.items():
            if annotation in simple and hasattr(obj, attribute):
                value = getattr(obj, attribute)
                assert type(value) is simple[annotation] or (
                    annotation == "float" and type(value) is int), (
                    f"{name}.{attribute}: the stub says {annotation}, the module gives "
                    f"{type(value).__name__}")
                checked += 1
    assert checked >= 40


def has_doc(obj):
    doc = inspect.getdoc(obj) or ""
    # pybind11 puts the signature(s) first: keep the text.
    text = [line for line in doc.splitlines()
            if line.strip() and not re.match(r"^(\d+\. )?\w+\(.*\)( -> .*)?$", line)
            and line.strip() != "Overloaded function."]
    return bool(text)


def test_everything_public_has_a_docstring():
    undocumented = []
    for name in jelly.__all__:
        obj = getattr(jelly, name)
        if inspect.isclass(obj):
            if not has_doc(obj):
                undocumented.append(name)
            for member, value in vars(obj).items():
                if member.startswith("_") or member in ("name", "value"):
                    continue
                if callable(value) or isinstance(value, property):
                    if not has_doc(value):
                        undocumented.append(f"{name}.{member}")
        elif callable(obj) and not has_doc(obj):
            undocumented.append(name)
    assert undocumented == []


def instances(tmp_path):
    """One instance of every public class of the module, by class name."""
    import numpy as np

    scene = jelly.load_scene(pathlib.Path(__file__).resolve().parents[2] / "scenes"
                             / "pinned_jelly.json", {"duration": 0.02, "output_interval": 0.005})
    sim = jelly.Simulator(scene)
    report = sim.run_until(0.02)
    path = str(tmp_path / "run.h5")
    with jelly.H5Recorder(path, sim, scene) as recorder:
        sim.add_observer(recorder)
        sim.run_until(0.06)
    model = sim.model

    class Pull(jelly.Force):
        def forces(self, t, x, v, f):
            pass

    class Watch(jelly.Observer):
        def on_frame(self, simulator):
            pass

    fit = jelly.fit_recording(path, free="ks", max_iterations=1, window=0.02)
    out = {
        "AnchorSpring": jelly.AnchorSpring(0, [0, 1, 0], 10.0),
        "ArkodeOptions": jelly.ArkodeOptions(), "Body": model.bodies[0],
        "Checkpoint": jelly.read_checkpoint(path), "ContactParams": jelly.ContactParams(),
        "CubeSpec": jelly.CubeSpec(), "DLPackExport": jelly.dlpack(np.zeros(3)),
        "DivergenceGuard": jelly.DivergenceGuard(), "Elevator": jelly.Elevator(),
        "ElevatorSpec": jelly.ElevatorSpec(), "ExternalForce": None, "FitOptions": jelly.FitOptions(),
        "FitResult": fit, "FittedParameter": fit.parameters[0], "Force": Pull(),
        "H5Recorder": recorder, "ImplicitEulerOptions": jelly.ImplicitEulerOptions(),
        "Integrator": sim.integrator, "IntegratorOptions": jelly.IntegratorOptions(),
        "Model": model, "Observer": Watch(), "Pins": model.pins, "Plane": jelly.Plane.slope(20),
        "ProjectiveDynamicsOptions": jelly.ProjectiveDynamicsOptions(),
        "VbdOptions": jelly.VbdOptions(), "XpbdOptions": jelly.XpbdOptions(),
        "RecorderOptions": jelly.RecorderOptions(), "Recording": jelly.read_recording(path),
        "Rollout": jelly.rollout(scene, [{}], 0.01, every=0.005), "RunReport": report,
        "Scene": scene, "Simulator": sim, "SimulatorOptions": jelly.SimulatorOptions(),
        "SimulatorSnapshot": sim.snapshot(), "SpringCoefficients": jelly.SpringCoefficients(),
        "SpringType": jelly.SpringType.shear, "Springs": model.springs,
        "State": sim.state, "StepResult": sim.step(), "Surface": model.bodies[0].surface,
        "Terrain": sim.terrains[0],
    }
    wind = jelly.Scene({"bodies": [{"kind": "cube", "n": 2, "forces": [
        {"kind": "wind", "velocity": [1, 0, 0], "drag": 0.1}]}],
        "integrator": {"name": "rk4"}, "duration": 1})
    out["ExternalForce"] = jelly.make_model(wind).external_forces[0]
    return out


# What does not pickle, and why: views into a simulator or model (pickle the model or the
# scene), live objects (a simulator: pickle its scene and a snapshot; a recorder writes a file;
# a subclass's Python state), and results made to be read, not stored.
NOT_PICKLED = {"Body", "Checkpoint", "DLPackExport", "Elevator", "ExternalForce", "FitResult",
               "FittedParameter", "Force", "H5Recorder", "Integrator", "Observer", "Pins",
               "Plane", "Simulator", "Springs", "StepResult", "Surface", "Terrain"}


def test_every_class_prints_and_pickles_or_says_it_does_not(tmp_path):
    import copy
    import pickle

    import numpy as np

    objects = instances(tmp_path)
    classes = {name for name in jelly.__all__ if inspect.isclass(getattr(jelly, name))
               and not issubclass(getattr(jelly, name), BaseException)}
    assert classes == set(objects), "a public class without an instance here"
    for name, obj in sorted(objects.items()):
        assert isinstance(obj, getattr(jelly, name)), name
        text = repr(obj)
        assert " object at 0x" not in text, f"{name} has no repr of its own: {text}"
        if name in NOT_PICKLED:
            continue
        back = pickle.loads(pickle.dumps(obj))
        assert type(back) is type(obj), name
        assert repr(back) == text or name in ("Scene",), name
        if name in ("Model", "State", "Rollout", "SimulatorSnapshot"):
            copy.deepcopy(obj)
    model = pickle.loads(pickle.dumps(objects["Model"]))
    original = objects["Model"]
    for field in ("mass", "rest_position"):
        assert getattr(model, field).tobytes() == getattr(original, field).tobytes()
    for field in ("a", "b", "ks", "kd", "rest_length", "type"):
        assert np.array_equal(getattr(model.springs, field), getattr(original.springs, field))
    assert repr(model.pins) == repr(original.pins) and len(model.bodies) == len(original.bodies)
    assert repr(model.bodies[0]) == repr(original.bodies[0])
    # A simulator of the unpickled model runs as one of the original.
    a, b = jelly.Simulator(original), jelly.Simulator(model)
    a.step(20)
    b.step(20)
    assert a.state.x.tobytes() == b.state.x.tobytes()


def test_import_leaves_numpy_unloaded_and_defaults_still_work():
    """`import jelly` does not import NumPy (most of its start-up, docs/CONTRIBUTING.md); an
    argument whose default is (0, 0, 0) still takes it: the slope passes through the origin."""
    import subprocess
    import sys
    code = ("import sys, jelly\n"
            "loaded = 'numpy' in sys.modules\n"
            "p = jelly.Plane.slope(20)\n"
            "print(loaded, p.signed_distance([0, 0, 0], 0.0), p.signed_distance([0, 1, 0], 0.0))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out[0] == "False"
    assert float(out[1]) == 0.0
    assert abs(float(out[2]) - 0.9396926207859084) < 1e-15  # cos 20 degrees
