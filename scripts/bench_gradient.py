#!/usr/bin/python3
"""The cost of one exact gradient (jelly.gradient, docs/gradients.md) against the forward run
alone: a cube of n^3 particles dropped onto a coulomb floor (implicit_euler, dt = 10 ms),
`steps` steps, loss on the final state. Three runs alternate in one process, `repeats` times:
the forward run (jelly.Simulator(scene) and sim.step() `steps` times), the gradient with respect
to 10 parameters (ks and kd of the 3 spring types, gravity, the particle mass) and with respect to
every particle's initial velocity (3 n^3 parameters). Prints best and median seconds and the
ratios of the medians, of wall time and of this process's CPU time (which a busy machine's other
processes do not inflate). With --contact: two cubes of n^3 particles pressed together in the air
(closing at 0.2 m/s: contact between the bodies inside the solve, friction 0.5) instead, the second
gradient with respect to both bodies' initial velocities (6 n^3 parameters).

    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_gradient.py [n] [steps] [repeats]
    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_gradient.py --contact 6 5 1
    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_gradient.py --newton 5 6 5 1
    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_gradient.py --free --pd 10 6 5 1

--newton K: implicit_euler with newton_iterations = K (the adjoint of the converged step).
--pd K: projective_dynamics with K iterations per step (the adjoint of its fixed point).
--free: no floor: the cube spins in the air (angular velocity (2, 5, 1) rad/s), so that the
springs stretch from the first step (the scene projective_dynamics' adjoint takes).
"""

import argparse
import os
import statistics
import time
import warnings

import numpy as np

import jelly


def integrator(args):
    if args.pd > 0:
        return {"name": "projective_dynamics", "dt": 0.01,
                "options": {"iterations": args.pd}}
    return {"name": "implicit_euler", "dt": 0.01}


def scene(n, overrides, args):
    body = {"kind": "cube", "name": "jelly", "n": n, "edge_length": 1.0,
            "origin": [-0.5, 0.05, -0.5], "particle_mass": 0.05,
            "velocity": [0.5, -1.0, 0.0],
            "springs": {t: {"ks": 2000, "kd": 2} for t in ("structural", "shear", "bending")}}
    if args.free:
        body["angular_velocity"] = [2.0, 5.0, 1.0]
        return jelly.Scene({"bodies": [body], "gravity": [0, -9.8, 0],
                            "integrator": integrator(args), "threads": 1, "duration": 1},
                           overrides)
    return jelly.Scene({
        "bodies": [{"kind": "cube", "name": "jelly", "n": n, "edge_length": 1.0,
                    "origin": [-0.5, 0.05, -0.5], "particle_mass": 0.05,
                    "velocity": [0.5, -1.0, 0.0],
                    "springs": {t: {"ks": 2000, "kd": 2} for t in
                                ("structural", "shear", "bending")}}],
        "gravity": [0, -9.8, 0],
        "terrains": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                      "contact": {"model": "coulomb", "restitution": 0, "friction": 1,
                                  "static_friction": 1}}],
        "integrator": {"name": "implicit_euler", "dt": 0.01},
        "threads": 1,
        "duration": 1,
    }, overrides)


def contact_scene(n, overrides):
    edge = 0.5
    gap = edge / (n - 1) * 1.02  # the facing layers just inside each other's contact reach

    def cube(name, x, vx):
        return {"kind": "cube", "name": name, "n": n, "edge_length": edge,
                "origin": [x, 0.0, 0.0], "particle_mass": 0.05, "velocity": [vx, 0.1, 0.0],
                "springs": {t: {"ks": 2000, "kd": 2} for t in
                            ("structural", "shear", "bending")}}

    return jelly.Scene({
        "bodies": [cube("left", -edge, 0.1), cube("right", gap, -0.1)],
        "gravity": [0, -9.8, 0],
        "body_contact": {"restitution": 0, "friction": 0.5, "static_friction": 0.5},
        "integrator": {"name": "implicit_euler", "dt": 0.01},
        "threads": 1,
        "duration": 1,
    }, overrides)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int, nargs="?", default=20, help="particles per edge")
    parser.add_argument("steps", type=int, nargs="?", default=20)
    parser.add_argument("repeats", type=int, nargs="?", default=3)
    parser.add_argument("--contact", action="store_true",
                        help="two cubes pressed together instead of one on a floor")
    parser.add_argument("--newton", type=int, default=1, help="newton_iterations")
    parser.add_argument("--pd", type=int, default=0,
                        help="projective_dynamics with this many iterations per step")
    parser.add_argument("--free", action="store_true", help="no floor: a spinning cube")
    args = parser.parse_args()
    n, steps, repeats = args.n, args.steps, args.repeats
    overrides = {"integrator.options.newton_iterations": args.newton} if args.newton > 1 else {}
    s = contact_scene(n, overrides) if args.contact else scene(n, overrides, args)
    bodies = 2 if args.contact else 1
    dt = 0.01

    def loss(x, v):
        return float(x[:, 0].sum() + 0.5 * (v * v).sum()), np.tile([1.0, 0, 0], (len(x), 1)), v

    def gradient(wrt):
        with warnings.catch_warnings():  # (held sliding viscosities: the cost is the same)
            warnings.simplefilter("ignore")
            return jelly.gradient(s, steps * dt, loss, wrt)

    def forward():
        sim = jelly.Simulator(s)
        sim.set_threads(1)
        for _ in range(steps):
            sim.step()

    ten = ["bodies[0].springs.%s.%s" % (t, k) for t in ("structural", "shear", "bending")
           for k in ("ks", "kd")] + ["gravity", "bodies[0].mass"]
    runs = {
        "forward": forward,
        "gradient, 10 parameters": lambda: gradient(ten),
        "gradient, %d parameters" % (3 * bodies * n ** 3):
            lambda: gradient(["bodies[%d].velocities" % b for b in range(bodies)]),
    }
    times = {name: [] for name in runs}
    cpu = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start, start_cpu = time.perf_counter(), time.process_time()
            run()
            times[name].append(time.perf_counter() - start)
            cpu[name].append(time.process_time() - start_cpu)
    name = f"projective_dynamics ({args.pd} iterations)" if args.pd > 0 else (
        f"implicit_euler (newton_iterations {args.newton})")
    print(f"{name}{', free' if args.free else ''}: "
          f"{bodies} x n = {n} ({bodies * n ** 3} particles), {steps} steps, load average "
          f"{os.getloadavg()[0]:.2f}")
    base = statistics.median(times["forward"])
    base_cpu = statistics.median(cpu["forward"])
    for name, t in times.items():
        c = statistics.median(cpu[name])
        print(f"{name:32s} best {min(t):8.3f} s  median {statistics.median(t):8.3f} s  "
              f"ratio {statistics.median(t) / base:5.2f}  cpu median {c:8.3f} s  "
              f"ratio {c / base_cpu:5.2f}")
    # One more gradient for what its passes did (not timed above).
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        raw = jelly._jelly._gradient(jelly.Simulator(s), steps, lambda x, v, f: loss(x, v), [],
                                     [], np.zeros((0, 3)), 0)
    print(f"backward solver {raw['backward_solver']}: {raw['backward_iterations'] / steps:.1f} "
          f"iterations per step; forward part {raw['forward_seconds']:.3f} s, backward pass "
          f"{raw['backward_seconds']:.3f} s; forward residual {raw['forward_residual']:.2g}")


if __name__ == "__main__":
    main()
