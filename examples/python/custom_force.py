#!/usr/bin/env python3
"""A force written in Python, inside the solver: a wind on the seed jelly, under RK4 and under
implicit Euler.

The seed jelly falls onto the 20-degree slope while a wind blows along +z: each particle feels
the drag F = c (w - v) (c = 0.5 N s/m, w = 3 m/s along z) on top of gravity and the springs.
`Wind` subclasses `jelly.Force`: its `forces()` adds the drag into f at every force evaluation
of the integrator (each RK4 stage), and its `jacobians()` gives dF/dv = -c I as a SciPy sparse
matrix, which implicit Euler takes into its linear solve (without it the run report's notes say
the force is treated explicitly). Each run is compared with the same wind as a scene force of
the body ({"kind": "wind", ...} in bodies[0].forces): the two agree to rounding.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/custom_force.py [--seconds 2]
        [--plot out/custom_force.png]
"""

import argparse
import pathlib

import numpy as np
import scipy.sparse

import jelly

SCENE = pathlib.Path(__file__).resolve().parents[2] / "scenes" / "seed_slope.json"
WIND, DRAG = np.array([0.0, 0.0, 3.0]), 0.5


class Wind(jelly.Force):
    """F = c (w - v) on every particle."""

    name = "python_wind"

    def forces(self, t, x, v, f):
        f += DRAG * (WIND - v)

    def jacobians(self, t, x, v):
        return None, -DRAG * scipy.sparse.identity(v.size, format="csr")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--plot", default=None, help="write a PNG of the centre of mass")
    args = parser.parse_args()

    paths = {}
    for integrator, dt in (("rk4", 0.001), ("implicit_euler", 0.01)):
        scene = jelly.load_scene(SCENE, [f"integrator.name={integrator}", f"integrator.dt={dt}"])
        python, calm = jelly.Simulator(scene), jelly.Simulator(scene)
        python.add_force(Wind())
        builtin = jelly.Simulator(scene.with_overrides({"bodies[0].forces": [
            {"kind": "wind", "velocity": WIND.tolist(), "drag": DRAG}]}))
        times, z = [], {"python": [], "scene": [], "calm": []}
        for sim in (python, builtin, calm):
            key = "python" if sim is python else "scene" if sim is builtin else "calm"
            report = sim.run_until(args.seconds,
                                   callback=lambda s, key=key: z[key].append(s.center_of_mass()[2]))
            if not report.ok:
                raise SystemExit(f"{integrator}: {report.brief()}")
            for note in report.notes:
                print(f"{integrator}: note: {note}")
            if key == "calm":
                times = np.arange(len(z["calm"])) * sim.options.output_interval
        drift = z["python"][-1] - z["calm"][-1]
        scene_drift = z["scene"][-1] - z["calm"][-1]
        print(f"{integrator}: drift along z after {args.seconds:g} s: Python force "
              f"{drift:+.9f} m, scene force {scene_drift:+.9f} m")
        paths[integrator] = (times, z)

    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 3.5))
        for integrator, (times, z) in paths.items():
            n = min(len(times), len(z["python"]))
            ax.plot(times[:n], np.array(z["python"][:n]), label=f"wind, Python ({integrator})")
            ax.plot(times[:n], np.array(z["scene"][:n]), "--", label=f"wind, scene ({integrator})")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("centre of mass z (m)")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=80)
        print(f"written: {args.plot}")


if __name__ == "__main__":
    main()
