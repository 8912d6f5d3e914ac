#!/usr/bin/env python3
"""Optimal control with exact gradients: swing a hanging jelly onto a target.

A small cube hangs from one pinned particle (implicit Euler, dt = 1/60 s). The pin may move
only within 15 cm of where it starts, but the jelly's centre of mass must end 0.6 m to the side
after one second: the pin has to swing it. The pin's positions at the end of every step (60 x 3
controls) are optimised with SciPy's L-BFGS-B, the loss and its gradient with respect to the
whole control sequence coming from one jelly.gradient call each (a forward run and its discrete
adjoint, docs/gradients.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/throw_with_pin.py [--iterations 60]
"""

import argparse

import numpy as np
import scipy.optimize

import jelly

DT = 1 / 60


def scene(steps):
    return jelly.Scene({
        "bodies": [{
            "kind": "cube", "name": "jelly", "n": 3, "edge_length": 0.3,
            "origin": [-0.15, 1.0, -0.15], "particle_mass": 0.05,
            "springs": {t: {"ks": 300, "kd": 1} for t in ("structural", "shear", "bending")},
            "pins": [{"region": {"min": [-0.05, 1.25, -0.05], "max": [0.05, 1.35, 0.05]}}]}],
        "gravity": [0, -9.8, 0],
        "terrains": [],
        "integrator": {"name": "implicit_euler", "dt": DT},
        "duration": steps * DT,
    })


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=1.0)
    parser.add_argument("--iterations", type=int, default=60)
    args = parser.parse_args()
    steps = int(round(args.seconds / DT))
    s = scene(steps)
    sim = jelly.Simulator(s)
    pin = int(sim.model.pins.particles[0])
    start = np.array(sim.state.x)[pin]
    n = len(np.array(sim.state.x))
    com0 = np.array(sim.state.x).mean(axis=0)
    goal = com0 + np.array([0.6, 0.0, 0.0])
    reach = 0.15  # m: how far the pin may move from where it starts

    def loss(x, v):
        miss = x.mean(axis=0) - goal
        dx = np.tile(miss / n, (n, 1))
        return 0.5 * float(miss @ miss), dx, np.zeros_like(v)

    def objective(flat):
        targets = flat.reshape(steps, 1, 3)
        value, grads = jelly.gradient(s, steps * DT, loss, ["pin_targets"], pins=[pin],
                                      pin_targets=targets)
        return value, grads["pin_targets"].ravel()

    hold = np.tile(start, (steps, 1, 1)).ravel()
    bounds = [(c - reach, c + reach) for c in hold]
    before = objective(hold)[0]
    result = scipy.optimize.minimize(objective, hold, jac=True, method="L-BFGS-B", bounds=bounds,
                                     options={"maxiter": args.iterations})
    after = result.fun
    print(f"controls: {steps} steps x 3 = {3 * steps}; L-BFGS-B iterations: {result.nit}, "
          f"gradients: {result.nfev}")
    print(f"miss distance of the centre of mass: held still {np.sqrt(2 * before):.4f} m, "
          f"optimised {np.sqrt(2 * after):.4f} m")
    path = result.x.reshape(steps, 3)
    print(f"the pin's largest excursion: {np.abs(path - start).max():.3f} m (allowed {reach} m)")


if __name__ == "__main__":
    main()
