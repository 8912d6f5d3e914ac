#!/usr/bin/env python3
"""A control loop: carry a hanging jelly to a goal by moving the particle it hangs from.

A small cube hangs from one pinned corner under implicit Euler. Every step a crane's controller
reads the jelly's centre of mass (observation) and sets the pin's velocity for the next step
(action, `sim.set_pin_target`): the pin heads for the goal and follows the load's swing (the
centre ahead of the pin), which damps it. The jelly is carried over and settles under the goal.
With --gains, the same episode again for each gain, each from the start (`sim.reset` to a
snapshot taken before the first step: state, clock and the pin's target of then).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/pin_controller.py [--seconds 6]
    PYTHONPATH=build/python /usr/bin/python3 examples/python/pin_controller.py --gains 0.5,2
"""

import argparse

import numpy as np

import jelly


def hanging_cube():
    spec = jelly.CubeSpec()
    spec.n, spec.edge_length, spec.origin = 4, 0.6, [-0.3, 1.0, -0.3]
    spec.particle_mass = 0.05
    options = jelly.IntegratorOptions()
    sim_options = jelly.SimulatorOptions()
    sim_options.dt = 1 / 120
    model = jelly.build_cube(spec)
    sim = jelly.Simulator(model, None, "implicit_euler", options, sim_options)
    top = jelly.cube_index(4, 0, 3, 0)  # a top corner
    sim.set_pin(top)
    return sim, top


def episode(sim, top, seconds, gain=1.0, verbose=True):
    """Carries the jelly for `seconds`; returns its centre's horizontal distance to the goal."""
    goal = np.array([1.5, 0.0, 0.5])  # where the centre should come to hang (x, z)
    sway, speed_limit = 2.0, 1.0
    dt = sim.options.dt
    pin = np.array(sim.state.x[top])
    for k in range(round(seconds / dt)):
        center = sim.center_of_mass()                       # observation
        # A crane's controller: the pin heads for the goal, and follows the load's swing
        # (centre ahead of the pin) to damp it.
        command = gain * (goal - pin) + sway * (center - pin)
        command[1] = 0.0                                    # only horizontal moves
        speed = np.linalg.norm(command)
        if speed > speed_limit:
            command *= speed_limit / speed
        sim.set_pin_target(top, pin, command)               # action: from here, at this speed
        assert sim.step().ok
        pin = np.array(sim.state.x[top])
        if verbose and k % 120 == 0:
            print(f"t = {sim.t:4.2f} s  centre {center[0]:+.3f} {center[2]:+.3f}  "
                  f"pin {pin[0]:+.3f} {pin[2]:+.3f}")
    center = sim.center_of_mass()
    return np.hypot(*(goal - center)[[0, 2]])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=6.0)
    parser.add_argument("--gains", default="",
                        help="comma-separated gains, each run from the start after the first")
    args = parser.parse_args()

    sim, top = hanging_cube()
    start = sim.snapshot()
    miss = episode(sim, top, args.seconds)
    print(f"after {args.seconds:g} s the centre is {miss:.3f} m from the goal")
    for gain in (float(g) for g in args.gains.split(",") if g):
        sim.reset(start)  # back to t = 0: the state, and the pin as it was
        miss = episode(sim, top, args.seconds, gain, verbose=False)
        print(f"gain {gain:g}: after {args.seconds:g} s the centre is {miss:.3f} m from the goal")


if __name__ == "__main__":
    main()
