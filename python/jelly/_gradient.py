"""jelly.gradient: exact gradients through implicit_euler or projective_dynamics (the discrete
adjoint, docs/gradients.md)."""

import re
import warnings
from typing import Any, Callable, Optional, Sequence

from . import _jelly

_SPRING_TYPES = ("structural", "shear", "bending")
_PATH = re.compile(r"^bodies\[(\d+)\]\.(.+)$")


def _steps(duration: float, dt: float) -> int:
    steps = int(round(duration / dt))
    if steps < 1 or abs(steps * dt - duration) > 1e-9 * max(1.0, abs(duration)):
        raise _jelly.InputError(
            f"duration: {duration!r} is not allowed; allowed: a positive multiple of the "
            f"integrator's dt ({dt!r} s)")
    return steps


def gradient(scene: Any, duration: float, loss: Callable, wrt: Sequence[str], *,
             frames: Optional[Sequence[int]] = None, pins: Sequence[int] = (),
             pin_targets: Any = None, checkpoint_every: int = 0) -> tuple:
    """The loss of a run of ``scene`` (implicit_euler or projective_dynamics) over ``duration``
    seconds and its exact gradient (docs/gradients.md).

    loss(x, v) -> (value, dL/dx, dL/dv): x, v the (N, 3) positions and velocities of the final
    state (or of each step index in ``frames``, 0..K with K = duration / dt, the terms summed).
    wrt: paths, each returned as a NumPy array:
      "bodies[i].springs.<structural|shear|bending>.<ks|kd>" (a 0-d array), "gravity" (3,),
      "bodies[i].mass" (the particle mass of body i, 0-d), "bodies[i].velocity" and
      "bodies[i].position" (3,: every particle moved together), "bodies[i].velocities" and
      "bodies[i].positions" ((N_i, 3): each particle's initial state), "pin_targets" (K, P, 3),
      "bodies[i].forces[k].force" (constant and point forces) or ".velocity" (wind's air
      velocity) (3,), "bodies[i].forces[k].drag" (wind, 0-d), "bodies[i].forces[k].gust" (0-d):
      the body's k-th external force as the scene lists it.
    pins / pin_targets: pinned particles (global indices) driven by a control sequence: before
    step k pin p moves in a straight line to pin_targets[k, p] (K x P x 3), where it ends the step.
    checkpoint_every: 0 keeps every step's state (9N doubles per step); S > 0 keeps a snapshot
    every S steps and runs each segment again during the backward pass (one more forward run,
    memory for S steps).
    Returns (value, {path: array}). Warns when sliding or bouncing contacts (terrain or between
    bodies) made the gradient approximate (a friction viscosity or restitution held fixed), when
    a Newton step did not converge, and when projective_dynamics' iterations stopped short of the
    fixed point (the gradient is that of the converged steps).
    """
    import numpy  # here, not at the top: `import jelly` does not load NumPy
    sim = _jelly.Simulator(scene)
    steps = _steps(float(duration), sim.options.dt)
    pins = [int(p) for p in pins]
    if pin_targets is None:
        if pins:
            raise _jelly.InputError("pin_targets: None is not allowed; allowed: an array of "
                                    f"shape ({steps}, {len(pins)}, 3) for the driven pins")
        targets = numpy.zeros((0, 3))
    else:
        targets = numpy.asarray(pin_targets, dtype=float)
        if targets.shape != (steps, len(pins), 3):
            raise _jelly.InputError(f"pin_targets: an array of shape {targets.shape} is not "
                                    f"allowed; allowed: shape ({steps}, {len(pins)}, 3)")
    model = sim.model
    bodies = model.bodies
    requests = []
    for path in wrt:
        requests.append(_parse(path, len(bodies)))

    def frame_loss(x, v, frame):
        return loss(x, v)

    raw = _jelly._gradient(sim, steps, frame_loss, list(frames or []), pins,
                           targets.reshape(-1, 3), int(checkpoint_every))
    held = (
        (raw["slide_steps"], "particle-step(s) held a sliding contact's friction viscosity fixed "
         "(set by its prediction or an earlier solve of the step)"),
        (raw["bounce_steps"], "particle-step(s) held a bouncing contact's restitution fixed"),
        (raw["pair_slide_steps"], "pair-step(s) of contact between bodies held a sliding pair's "
         "friction viscosity fixed (set by its prediction or an earlier solve of the step)"),
        (raw["pair_bounce_steps"], "pair-step(s) of contact between bodies held a bouncing "
         "pair's restitution fixed"),
        (raw["pair_projected_steps"], "step(s) held the projection of an overlap between bodies "
         "deeper than 0.5 % of the radii fixed"),
        (raw["newton_unconverged_steps"], "step(s) stopped Newton's iterations above "
         "newton_tolerance (the adjoint is of the converged step)"))
    for count, what in held:
        if count:
            warnings.warn(f"jelly.gradient: {count} {what}; the gradient there is approximate "
                          "(docs/gradients.md)", stacklevel=2)
    if raw["forward_residual"] > 1e-6:
        warnings.warn("jelly.gradient: projective_dynamics' iterations stopped with a residual "
                      f"of {raw['forward_residual']:.2g} times the step's first; the gradient is "
                      "that of the converged steps (more iterations or a tolerance: "
                      "docs/gradients.md)", stacklevel=2)
    out = {}
    for path, (body, what) in zip(wrt, requests):
        if isinstance(what, tuple) and what[0] == "force":
            out[path] = _force_gradient(raw, path, body, what[1], what[2])
        elif what == "gravity":
            out[path] = raw["gravity"].copy()
        elif what == "pin_targets":
            out[path] = raw["pin_targets"].reshape(steps, len(pins), 3)
        elif isinstance(what, tuple):  # (ks or kd, spring type)
            out[path] = numpy.array(raw[what[0]][3 * body + what[1]])
        elif what == "mass":
            out[path] = numpy.array(raw["particle_mass"][body])
        else:
            b = bodies[body]
            rows = slice(b.first_particle, b.first_particle + b.num_particles)
            per_particle = raw["velocity" if what.startswith("velocit") else "position"][rows]
            # bodies[i].velocity / position: every particle moved together (the scene's field).
            out[path] = per_particle.sum(axis=0) if what in ("velocity", "position") \
                else per_particle.copy()
    return raw["loss"], out


_FORCE = re.compile(r"^forces\[(\d+)\]\.(force|velocity|drag|gust)$")


def _force_gradient(raw, path: str, body: int, k: int, field: str):
    """The gradient of body `body`'s k-th external force's `field` from the raw result."""
    import numpy

    indices = [e for e, b in enumerate(raw["force_body"]) if b == body]
    if k >= len(indices):
        raise _jelly.InputError(f"wrt: '{path}' is not allowed; allowed: a force index below "
                                f"{len(indices)} (the forces of body {body})")
    e = indices[k]
    kind = raw["force_kind"][e]
    fields = {"constant": ("force", "gust"), "point": ("force", "gust"),
              "wind": ("velocity", "drag", "gust")}[kind]
    if field not in fields:
        raise _jelly.InputError(f"wrt: '{path}' is not allowed; allowed: for a {kind} force, "
                                + ", ".join(fields))
    if field in ("force", "velocity"):
        return raw["force_vector"][e].copy()
    return numpy.array(raw["force_drag" if field == "drag" else "force_gust"][e])


def _parse(path: str, bodies: int):
    allowed = ("'gravity', 'pin_targets', 'bodies[i].springs.<structural|shear|bending>."
               "<ks|kd>', 'bodies[i].mass', 'bodies[i].velocity', 'bodies[i].position', "
               "'bodies[i].velocities', 'bodies[i].positions', "
               "'bodies[i].forces[k].<force|velocity|drag|gust>'")
    if path in ("gravity", "pin_targets"):
        return None, path
    match = _PATH.match(path)
    if match is None:
        raise _jelly.InputError(f"wrt: '{path}' is not allowed; allowed: {allowed}")
    body = int(match.group(1))
    if body >= bodies:
        raise _jelly.InputError(f"wrt: '{path}' is not allowed; allowed: a body index below "
                                f"{bodies}")
    rest = match.group(2)
    force = _FORCE.match(rest)
    if force is not None:
        return body, ("force", int(force.group(1)), force.group(2))
    if rest in ("mass", "particle_mass", "velocity", "position", "velocities", "positions"):
        return body, "mass" if rest == "particle_mass" else rest
    parts = rest.split(".")
    if len(parts) == 3 and parts[0] == "springs" and parts[1] in _SPRING_TYPES and \
            parts[2] in ("ks", "kd"):
        return body, (parts[2], _SPRING_TYPES.index(parts[1]))
    raise _jelly.InputError(f"wrt: '{path}' is not allowed; allowed: {allowed}")
