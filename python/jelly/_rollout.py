"""Batched rollouts: many runs of one scene with different parameters, run by the C++ library on a
pool of threads without the GIL, their positions (and velocities) returned as NumPy arrays
[runs, frames, particles, 3]. docs/python.md, "Batched rollouts".
"""

from __future__ import annotations

import json
import os
from typing import Any, Mapping, Optional, Sequence, Union

from . import _jelly
from ._scene import Overrides, Scene, _split, assignments, load_scene

__all__ = ["rollout"]


def rollout(scene: Union[Scene, str, os.PathLike], overrides_per_run: Sequence[Overrides],
            duration: float, every: Optional[float] = None, velocities: bool = False,
            threads: int = 0) -> "_jelly.Rollout":
    """Runs the scene once per item of ``overrides_per_run`` (each a {path: value} mapping or a
    list of 'path=value' strings, as ``Scene.with_overrides`` and ``jelly run --set`` take
    them: ``springs.structural.ks``, ``bodies[0].velocity``, ``gravity``, ``integrator.dt``,
    ``integrator.name``, ...) for ``duration`` seconds, and returns a ``jelly.Rollout``:
    ``positions`` [runs, frames, particles, 3] (``velocities`` too when asked), ``times``,
    ``status`` and ``reasons`` per run.

    Frames are kept every ``every`` seconds from t = 0 (0: every step; None: the scene's
    output_interval), as a Simulator's observers see them. The runs go ``threads`` at a time
    (0: one per core) on the C++ side, with the GIL released; each run's frames are the same bits
    as a Simulator of its scene run alone, whatever the thread count. A run that diverges or
    fails stops alone (its status says why, its later frames are NaN); the others go on.

    Raises InputError before any run starts for an invalid override (naming
    ``overrides_per_run[k]`` and the scene's field), an override of ``duration`` or
    ``output_interval`` (the rollout's own), runs whose particle counts differ (one array holds
    them all), or arrays that would not fit in memory.
    """
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    if isinstance(overrides_per_run, (str, bytes, Mapping)):
        raise TypeError("rollout: overrides_per_run is a list with one item (a {path: value} "
                        "mapping or a list of 'path=value' strings) per run")
    if every is not None and not every >= 0:
        raise _jelly.InputError(f"every = {every} is invalid: an interval >= 0 (s; 0 = every "
                                "step, None = the scene's output_interval)")
    runs = [_full_json_paths(scene, assignments(overrides)) for overrides in overrides_per_run]
    return _jelly._rollout(scene.to_json(), runs, scene._name, scene.base_directory,
                           float(duration), -1.0 if every is None else float(every),
                           bool(velocities), int(threads))


def _full_json_paths(scene: Scene, todo: list[str]) -> list[str]:
    """Overrides of a scene's source written for its full JSON (to_json(), which rollout
    parses): a one-cube scene file's ``springs...`` and ``cube.<field>`` are ``bodies[0]...``
    there."""
    source: Any = None
    out = []
    for assignment in todo:
        path, sep, value = assignment.partition("=")
        steps = _split(path)
        if steps and steps[0] in ("springs", "cube"):
            if source is None:
                source = json.loads(scene.source_json)
            if isinstance(source, dict) and "bodies" not in source:
                head = "bodies[0]" + (".springs" if steps[0] == "springs" else "")
                rest = path[len(steps[0]):]
                path = head + rest
        out.append(path + sep + value)
    return out
