#!/usr/bin/env python3
"""Drive a simulation step by step with a force computed in Python (NumPy).

The seed jelly falls onto the 20-degree slope while a wind blows along +z: each particle feels
the drag F = c (w - v) (c = 0.5 N s/m, w = 3 m/s along z) on top of gravity and the springs.
The solver knows nothing of the wind: before each step the script reads the velocities (a view
of the C++ memory, no copy) and applies the wind's impulse, v += dt F / m, through the explicit
setter (operator splitting: first order in dt). A third run gives the body the same wind as a
scene force ({"kind": "wind", "velocity": [0, 0, 3], "drag": 0.5} in bodies[0].forces), which
the C++ solver applies inside its steps: the two drifts agree to O(dt).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/custom_force.py [--seconds 2]
        [--plot out/custom_force.png]
"""

import argparse
import pathlib

import numpy as np

import jelly

SCENE = pathlib.Path(__file__).resolve().parents[2] / "scenes" / "seed_slope.json"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--plot", default=None, help="write a PNG of the centre of mass")
    args = parser.parse_args()

    scene = jelly.load_scene(SCENE)
    windy, calm = jelly.Simulator(scene), jelly.Simulator(scene)
    dt = windy.options.dt
    mass = windy.model.mass[:, None]  # (N, 1) view
    wind, drag = np.array([0.0, 0.0, 3.0]), 0.5
    builtin = jelly.Simulator(scene.with_overrides({"bodies[0].forces": [
        {"kind": "wind", "velocity": wind.tolist(), "drag": drag}]}))

    times, path_windy, path_calm, path_builtin = [], [], [], []
    steps = round(args.seconds / dt)
    for k in range(steps + 1):
        if k % 100 == 0:
            times.append(windy.t)
            path_windy.append(windy.center_of_mass())
            path_calm.append(calm.center_of_mass())
            path_builtin.append(builtin.center_of_mass())
        if k == steps:
            break
        v = windy.state.v  # no copy
        windy.state.v = v + dt * drag * (wind - v) / mass
        for sim in (windy, calm, builtin):
            result = sim.step()
            if not result.ok:
                raise SystemExit(f"step failed: {result.message}")

    path_windy, path_calm = np.array(path_windy), np.array(path_calm)
    path_builtin = np.array(path_builtin)
    for t, a, b in zip(times[::5], path_windy[::5], path_calm[::5]):
        print(f"t = {t:4.2f} s  centre of mass z: windy {a[2]:+.3f} m, calm {b[2]:+.3f} m")
    print(f"drift along z after {args.seconds:g} s: {path_windy[-1, 2] - path_calm[-1, 2]:+.6f} m")
    print(f"drift along z with the scene's wind force: "
          f"{path_builtin[-1, 2] - path_calm[-1, 2]:+.6f} m")

    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.plot(times, path_windy[:, 2], label="with wind (Python)")
        ax.plot(times, path_builtin[:, 2], "--", label="with wind (scene force)")
        ax.plot(times, path_calm[:, 2], label="without")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("centre of mass z (m)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=80)
        print(f"written: {args.plot}")


if __name__ == "__main__":
    main()
