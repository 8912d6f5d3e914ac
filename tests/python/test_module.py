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
