"""jelly: a mass-spring soft-body solver (C++17) in Python.

Scenes (``load_scene``, attributes by JSON path), simulation with NumPy views of the C++ state
(``Simulator``), batched rollouts into NumPy arrays (``rollout``), recordings (``H5Recorder``, ``read_recording``, checkpoints), fitting
(``fit_recording``) and parameter sweeps on Dask (``sweep``). See docs/python.md.
"""

import os as _os
from typing import Any as _Any, Optional as _Optional, Union as _Union

from . import _jelly
from ._jelly import (  # noqa: F401  (the C++ API, one binding file per module folder)
    AnchorSpring, ArkodeOptions, Body, Checkpoint, ContactParams, CubeSpec, DivergenceGuard,
    DLPackExport, dlpack,
    Elevator, ElevatorSpec, ExternalForce, Force, H5Recorder,
    ImplicitEulerOptions, InputError, Integrator, IntegratorOptions, Model, Observer, Pins, Plane,
    ProjectiveDynamicsOptions, RecorderOptions, Recording, Rollout, RunReport, SimulatorOptions,
    SimulatorSnapshot, Simulator,
    SpringCoefficients, Springs, SpringType, State, StepResult, Surface, Terrain, VbdOptions,
    XpbdOptions, __version__,
    angular_momentum, apply_override, body_kinds, build_cube, center_of_mass, check_same_scene,
    contact_models, cube_index, cube_particle_count, cube_spring_count, describe_recording,
    elastic_energy, gravitational_energy, integrator_infos, integrator_names, kinetic_energy,
    linear_momentum, make_model, make_terrain, read_checkpoint, read_recording,
    initial_state, rest_state, restore, scene_to_json, spring_type_names, terrain_kinds, total_energy,
    write_xdmf_for_recording)
if hasattr(_jelly, "FitOptions"):  # the component fit (a jelly built with JELLY_WITH_FIT)
    from ._jelly import FitOptions, FitResult, FittedParameter, parse_free_parameters  # noqa: F401
from ._scene import Scene, load_scene
from ._rollout import rollout
from ._sweep import sweep, sweep_points
from ._gradient import gradient

_FIT_KEYWORDS = ("free", "gradients", "window", "initial", "max_iterations", "function_tolerance",
                 "gradient_tolerance", "parameter_tolerance", "fit_restart_velocities",
                 "relative_step", "num_threads", "compute_covariance", "progress_to_stdout")


def fit_recording(recording: _Union[Recording, str, _os.PathLike],
                  options: _Optional["FitOptions"] = None, *,
                  write_scene: _Optional[_Union[str, _os.PathLike]] = None,
                  **keywords: _Any) -> "FitResult":
    """Fits spring and damper coefficients to a recording (a Recording or the path of a file
    written by ``jelly run -o`` or H5Recorder with a scene), as ``jelly fit`` does: the terrains,
    integrator and dt come from the scene stored in it.

    Options are a FitOptions and/or keywords of its fields: free ('ks,kd', the default), window
    (0.1 s), initial ({'ks': 1400}), max_iterations (50), ... write_scene: also write the
    recording's scene with the fitted values (``jelly fit --write-scene``). Returns a FitResult
    (``print(result)`` prints jelly fit's report); the GIL is released while fitting.
    """
    if not hasattr(_jelly, "FitOptions"):
        raise InputError("fit_recording needs jelly's component fit: this jelly was built without "
                         "it (JELLY_WITH_FIT=OFF)")
    if isinstance(recording, (str, _os.PathLike)):
        recording = read_recording(_os.fspath(recording))
    if write_scene is not None:
        # Checked before the fit, as jelly fit --write-scene does: never the file it reads.
        target = _os.fspath(write_scene)
        source = getattr(recording, "path", "")
        if source and _os.path.exists(target) and _os.path.exists(source) \
                and _os.path.samefile(target, source):
            raise InputError(f"write_scene '{target}' is the recording '{source}' (the same "
                             "file): the fitted scene would overwrite it; choose another name")
    chosen = FitOptions()
    if options is not None:
        for name in _FIT_KEYWORDS:
            setattr(chosen, name, getattr(options, name))
    for name, value in keywords.items():
        if name not in _FIT_KEYWORDS:
            raise TypeError(f"fit_recording() got an unknown option '{name}'; options: "
                            + ", ".join(_FIT_KEYWORDS))
        setattr(chosen, name, value)
    result = _jelly._fit_recording(recording, chosen)
    if write_scene is not None:
        fitted_scene(recording, result).save(write_scene)
    return result


def fitted_scene(recording: Recording, result: "FitResult") -> Scene:
    """The recording's scene with the fitted coefficients written into its spring types."""
    return Scene(scene_to_json(_jelly._fitted_scene(recording, result)))


def _recording_scene(self: Recording) -> Scene:
    """The scene the recording was made from (InputError if it stores none)."""
    if not self.scene_json:
        raise InputError("the recording stores no scene (it was not written from a scene)")
    return Scene(self.scene_json, (), "recording")


Recording.scene = property(_recording_scene, doc=_recording_scene.__doc__)

# Option and spec classes: plain values whose state is their read-write fields (CubeSpec also
# its springs' coefficients). They pickle (Dask sends them, copy.deepcopy copies them) and print
# as their fields.
_OPTION_CLASSES = (ArkodeOptions, ContactParams, CubeSpec, DivergenceGuard, ElevatorSpec,
                   ImplicitEulerOptions, IntegratorOptions, ProjectiveDynamicsOptions,
                   RecorderOptions, SimulatorOptions, VbdOptions, XpbdOptions)
if hasattr(_jelly, "FitOptions"):
    _OPTION_CLASSES += (FitOptions,)


def _option_fields(cls: type) -> list:
    return [name for name, value in vars(cls).items()
            if isinstance(value, property) and value.fset is not None and not name.startswith("_")]


def _option_state(obj: _Any) -> dict:
    state = {name: getattr(obj, name) for name in _option_fields(type(obj))}
    if isinstance(obj, CubeSpec):
        state["springs"] = {t: (obj.springs(t).ks, obj.springs(t).kd) for t in spring_type_names()}
    return state


def _options_from_state(cls: type, state: dict) -> _Any:
    """An option or spec object from its fields (unpickling)."""
    obj = cls()
    for name, value in state.items():
        if name == "springs" and cls is CubeSpec:
            for t, (ks, kd) in value.items():
                obj.set_springs(t, ks, kd)
        else:
            setattr(obj, name, value)
    return obj


def _option_reduce(self: _Any) -> tuple:
    return (_options_from_state, (type(self), _option_state(self)))


def _option_repr(self: _Any) -> str:
    fields = ", ".join(f"{name}={value!r}" for name, value in _option_state(self).items())
    return f"{type(self).__name__}({fields})"


for _cls in _OPTION_CLASSES:
    _cls.__reduce__ = _option_reduce
    _cls.__repr__ = _option_repr


def _state_reduce(self: State) -> tuple:
    import numpy
    return (State, (numpy.array(self.x), numpy.array(self.v), self.t))


State.__reduce__ = _state_reduce  # pickles and deep-copies as a copy of its arrays
AnchorSpring.__reduce__ = lambda self: (
    AnchorSpring, (self.particle, tuple(self.target), self.stiffness, self.damping))
SpringCoefficients.__reduce__ = lambda self: (_options_from_state, (SpringCoefficients,
                                                                     {"ks": self.ks,
                                                                      "kd": self.kd}))

# Classes to subclass in Python: their instances print as the subclass's name.
Force.__repr__ = lambda self: f"<jelly.Force {type(self).__name__}>"
Observer.__repr__ = lambda self: f"<jelly.Observer {type(self).__name__}>"

__all__ = sorted(name for name in dir() if not name.startswith("_"))
