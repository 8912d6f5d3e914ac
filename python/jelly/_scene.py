"""Scenes whose fields read and write as attributes, by their JSON paths.

A Scene keeps the JSON text it was made from (with every change applied to it) and the C++ scene
parsed from that text. Reading ``scene.springs.structural.ks`` looks the path up in the scene's
full JSON (``to_json()``: every field written out, defaults included). Writing
``scene.springs.structural.ks = 2400`` is the override ``springs.structural.ks=2400`` of
``jelly run --set``: the C++ ``apply_override`` edits the JSON and the C++ parser validates the
whole scene again, so a bad value raises ``jelly.InputError`` naming its JSON path and leaves the
scene unchanged. Nothing here knows the scene's fields: whatever the C++ format grows (bodies,
registries of kinds) reads and writes the same way.
"""

from __future__ import annotations

import copy as _copy
import json
import os
import stat
from typing import Any, Iterable, Iterator, Mapping, Union

from . import _jelly

__all__ = ["Scene", "load_scene"]

Overrides = Union[Iterable[str], Mapping[str, Any]]


def _json_value(value: Any) -> str:
    """A Python value as the JSON text of an override's right-hand side."""
    if isinstance(value, (_Node, _List)):
        value = value._value()
    if hasattr(value, "tolist"):  # NumPy arrays and scalars
        value = value.tolist()
    return json.dumps(value)


def assignments(overrides: Overrides) -> list[str]:
    """Overrides as 'path=value' strings: strings pass through, a mapping's values become JSON."""
    if isinstance(overrides, Mapping):
        return [f"{path}={_json_value(value)}" for path, value in overrides.items()]
    if isinstance(overrides, str):
        raise TypeError("overrides: a list of 'path=value' strings or a {path: value} mapping, "
                        "not a single string")
    return [str(o) for o in overrides]


def _child(path: str, key: Union[str, int]) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def _split(path: str) -> list[Union[str, int]]:
    """'terrains[0].contact.model' or 'terrains.0.contact.model' -> ['terrains', 0, ...]."""
    steps: list[Union[str, int]] = []
    for segment in path.split("."):
        name, _, rest = segment.partition("[")
        if name:
            steps.append(int(name) if name.isdigit() else name)
        while rest:
            index, _, rest = rest.partition("]")
            steps.append(int(index))
            rest = rest[1:] if rest.startswith("[") else rest
    return steps


class Scene(_jelly._Scene):
    """A scene (docs/scenes.md): fields are attributes (``scene.integrator.dt``), lists index
    (``scene.terrains[0].contact.restitution``), every write is validated by the C++ parser.

    ``Scene(json_text_or_dict, overrides=(), source="scene", base_directory="")``;
    ``jelly.load_scene(path)`` reads a file. Files the scene names (a body's ``file``) are
    relative to ``base_directory`` (``""``: the current directory; ``load_scene`` gives the scene
    file's folder, as ``jelly run`` does). ``jelly.Simulator(scene)`` builds what ``jelly run``
    builds from the same scene.
    """

    def __init__(self, json_text: Union[str, Mapping[str, Any]], overrides: Overrides = (),
                 source: str = "scene", base_directory: Union[str, os.PathLike] = "") -> None:
        if isinstance(json_text, Mapping):
            json_text = json.dumps(json_text)
        base = os.path.abspath(os.fspath(base_directory)) if os.fspath(base_directory) else ""
        todo = assignments(overrides)
        for assignment in todo:
            json_text = _override_target(json_text, assignment, source, base)
        super().__init__(json_text, todo, source, base)  # validates, C++ messages
        for assignment in todo:
            json_text = _jelly.apply_override(json_text, assignment)
        object.__setattr__(self, "_source", json_text)
        object.__setattr__(self, "_name", source)
        object.__setattr__(self, "_base", base)
        object.__setattr__(self, "_cache", None)

    # --- whole-scene operations -------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The scene's full JSON (every field, defaults included) as a new dict."""
        return _copy.deepcopy(self._full())

    def get(self, path: str) -> Any:
        """The value at a JSON path ('bodies[0].springs.structural.ks', 'terrains[0].kind'), as
        plain Python data (a copy). Raises KeyError for a path the scene does not have.

        Paths read the full JSON (to_json()), where every scene has its ``bodies``; a one-cube
        scene file's own keys ``cube`` and ``springs`` (which the full JSON writes as bodies[0])
        read as the file wrote them."""
        value: Any = self._full()
        steps = _split(path)
        if steps and steps[0] not in value:
            alias = _one_cube_alias(steps, value)
            if alias is not None:  # the same field as the parser read it (1400 -> 1400.0)
                steps = alias
            else:
                value = self._source_dict()
        for step in steps:
            try:
                value = value[step]
            except (KeyError, IndexError, TypeError):
                raise KeyError(f"the scene has no field '{path}'") from None
        return _copy.deepcopy(value)

    def set(self, path: str, value: Any) -> None:
        """Sets the value at a JSON path (as ``jelly run --set path=value``) and validates the
        scene; raises InputError naming the path, leaving the scene unchanged."""
        self.update({path: value})

    def update(self, overrides: Overrides) -> None:
        """Applies several overrides ({path: value} or 'path=value' strings) at once, validated
        together; raises InputError and leaves the scene unchanged if the result is invalid."""
        text = self._source
        for assignment in assignments(overrides):
            text = _jelly.apply_override(
                _override_target(text, assignment, self._name, self._base), assignment)
        self._assign(text, self._name, self._base)  # raises before anything changes
        object.__setattr__(self, "_source", text)
        object.__setattr__(self, "_cache", None)

    def with_overrides(self, overrides: Overrides) -> "Scene":
        """A new scene: this one with overrides applied ({path: value} or 'path=value')."""
        return Scene(self._source, overrides, self._name, self._base)

    def copy(self) -> "Scene":
        """An independent copy."""
        return Scene(self._source, (), self._name, self._base)

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the full JSON (to_json()) to a file: beside it first, then renamed, so that a
        failed write leaves an existing file as it was."""
        path = os.fspath(path)
        partial = f"{path}.partial-{os.getpid()}"
        try:
            with open(partial, "w", encoding="utf-8") as f:
                f.write(self.to_json())
            os.replace(partial, path)
        except BaseException:
            if os.path.exists(partial):
                os.remove(partial)
            raise

    @property
    def source_json(self) -> str:
        """The JSON the scene was made from, with every change applied (only the fields that
        were written; to_json() writes them all)."""
        return self._source

    @property
    def base_directory(self) -> str:
        """The absolute folder that files named in the scene are relative to ("" = the current
        directory): the scene file's folder for load_scene."""
        return self._base

    # --- attribute access by JSON path ---------------------------------------------------------
    def _full(self) -> dict[str, Any]:
        if self._cache is None:
            object.__setattr__(self, "_cache", json.loads(self.to_json()))
        return self._cache

    def _source_dict(self) -> dict[str, Any]:
        return json.loads(self._source)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        full = self._full()
        if name not in full:
            source = self._source_dict()
            if name in source:  # a one-cube scene file's "cube" and "springs"
                return _wrap(self, name, source[name])
            raise AttributeError(f"the scene has no field '{name}'; its fields: "
                                 + ", ".join(full))
        return _wrap(self, name, full[name])

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_") or hasattr(type(self), name):
            raise AttributeError(f"'{name}' is not a scene field and cannot be set")
        self.set(name, value)

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self._full()) | set(self._source_dict()))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, _jelly._Scene):
            return NotImplemented
        return self.to_json() == other.to_json()

    __hash__ = None  # type: ignore[assignment]  # mutable

    def __repr__(self) -> str:
        full = self._full()
        return (f"<jelly.Scene '{self._name}': integrator {full['integrator']['name']}, "
                f"dt {full['integrator']['dt']}, duration {full['duration']}>")

    def __reduce__(self):
        return (Scene, (self._source, (), self._name, self._base))

    def __copy__(self) -> "Scene":
        return self.copy()

    def __deepcopy__(self, memo: dict) -> "Scene":
        return self.copy()


def _override_target(text: str, assignment: str, source: str, base: str = "") -> str:
    """The JSON an override applies to: the scene's text, unless the path indexes a list that
    only the full JSON has (``bodies[0]...`` of a one-cube scene file written with ``cube`` and
    ``springs``): then the full JSON, the same scene with its bodies."""
    steps = _split(assignment.partition("=")[0])
    if len(steps) < 2 or not isinstance(steps[0], str) or not isinstance(steps[1], int):
        return text
    try:
        own = json.loads(text)
    except ValueError:
        return text  # the C++ parser says what is wrong with it
    if not isinstance(own, dict) or steps[0] in own:
        return text
    full = json.loads(_jelly._Scene(text, [], source, base).to_json())
    return json.dumps(full) if isinstance(full.get(steps[0]), list) else text


def _one_cube_alias(steps: list[Union[str, int]], full: dict[str, Any]):
    """The full JSON's path of a one-cube scene file's ``springs...`` or ``cube.<field>`` path
    (``bodies[0].springs...``, ``bodies[0].<field>``), or None when it has none."""
    bodies = full.get("bodies")
    if not isinstance(bodies, list) or len(bodies) != 1:
        return None
    if steps[0] == "springs":
        alias = ["bodies", 0, *steps]
    elif steps[0] == "cube" and len(steps) > 1:
        alias = ["bodies", 0, *steps[1:]]
    else:
        return None
    value: Any = full
    for step in alias:
        try:
            value = value[step]
        except (KeyError, IndexError, TypeError):
            return None
    return alias


def _wrap(scene: Scene, path: str, value: Any) -> Any:
    if isinstance(value, dict):
        return _Node(scene, path)
    if isinstance(value, list):
        return _List(scene, path)
    return value


class _Node:
    """A JSON object of a scene: its keys read and write as attributes or items."""

    __slots__ = ("_scene", "_path")

    def __init__(self, scene: Scene, path: str) -> None:
        object.__setattr__(self, "_scene", scene)
        object.__setattr__(self, "_path", path)

    def _value(self) -> dict[str, Any]:
        return self._scene.get(self._path)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        value = self._value()
        if name not in value:
            raise AttributeError(f"the scene has no field '{_child(self._path, name)}'; fields "
                                 f"of {self._path}: " + ", ".join(value))
        path = _child(self._path, name)
        if not isinstance(value[name], (dict, list)):
            return self._scene.get(path)  # as the parser read it
        return _wrap(self._scene, path, value[name])

    def __setattr__(self, name: str, value: Any) -> None:
        self._scene.set(_child(self._path, name), value)

    def __getitem__(self, key: str) -> Any:
        try:
            return self.__getattr__(key)
        except AttributeError as e:
            raise KeyError(str(e)) from None

    def __setitem__(self, key: str, value: Any) -> None:
        self._scene.set(_child(self._path, key), value)

    def __contains__(self, key: object) -> bool:
        return key in self._value()

    def __iter__(self) -> Iterator[str]:
        return iter(self._value())

    def __len__(self) -> int:
        return len(self._value())

    def keys(self):
        return self._value().keys()

    def to_dict(self) -> dict[str, Any]:
        return self._value()

    def __dir__(self) -> list[str]:
        return sorted(self._value())

    def __eq__(self, other: object) -> bool:
        if isinstance(other, (_Node, dict)):
            return self._value() == (other._value() if isinstance(other, _Node) else other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return repr(self._value())


class _List:
    """A JSON array of a scene: elements read and write by index."""

    __slots__ = ("_scene", "_path")

    def __init__(self, scene: Scene, path: str) -> None:
        self._scene = scene
        self._path = path

    def _value(self) -> list[Any]:
        return self._scene.get(self._path)

    def _index(self, i: int) -> int:
        n = len(self._value())
        j = i + n if i < 0 else i
        if not 0 <= j < n:
            raise IndexError(f"{self._path}[{i}] does not exist ({self._path} has {n} elements)")
        return j

    def __getitem__(self, i: Union[int, slice]) -> Any:
        if isinstance(i, slice):
            return self._value()[i]
        j = self._index(i)
        return _wrap(self._scene, _child(self._path, j), self._value()[j])

    def __setitem__(self, i: int, value: Any) -> None:
        self._scene.set(_child(self._path, self._index(i)), value)

    def __len__(self) -> int:
        return len(self._value())

    def __iter__(self) -> Iterator[Any]:
        return (self[i] for i in range(len(self)))

    def to_list(self) -> list[Any]:
        return self._value()

    def __array__(self, dtype=None):
        import numpy
        return numpy.asarray(self._value(), dtype=dtype)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, (_List, list, tuple)):
            return self._value() == (other._value() if isinstance(other, _List) else list(other))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return repr(self._value())


def load_scene(path: Union[str, os.PathLike], overrides: Overrides = ()) -> Scene:
    """Reads and validates a scene file (docs/scenes.md), applying overrides first ('path=value'
    strings as ``jelly run --set`` takes them, or a {path: value} mapping). Raises InputError
    naming the JSON path of the first invalid field."""
    path = os.fspath(path)
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # a pipe or a device: open() would block
            _jelly._load_scene(path)  # raises the C++ InputError naming what the path is
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError:
        _jelly._load_scene(path)  # raises the C++ InputError for an unreadable file
        raise
    return Scene(text, overrides, path, os.path.dirname(os.path.abspath(path)))
