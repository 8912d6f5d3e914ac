#!/usr/bin/env python3
"""Fit spring and damper coefficients to a recording, as `jelly fit` does, from Python.

Records a small jelly (3 x 3 x 3) dropped 0.3 m onto a floor (rk4) with ks = 1000, kd = 20, then fits ks and
kd from a start of 1400 and 30, prints jelly fit's report and writes the fitted scene.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fit_recording.py [--out out/fit]
"""

import argparse
import os
import pathlib

import jelly

SCENE = pathlib.Path(__file__).resolve().parents[2] / "scenes" / "drop_coulomb.json"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/fit", help="output folder")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    recording_path = os.path.join(args.out, "recording.h5")

    truth = {"ks": 1000, "kd": 20}
    scene = jelly.load_scene(SCENE, {"cube.n": 3, "cube.origin": [-1, 0.3, -1],
                                     "integrator.name": "rk4", "output_interval": 0.01,
                                     "duration": 0.5,
                                     **{f"springs.{t}": truth for t in jelly.spring_type_names()}})
    sim = jelly.Simulator(scene)
    options = jelly.RecorderOptions()
    options.overwrite = True  # this example's own file of an earlier run
    with jelly.H5Recorder(recording_path, sim, scene, options) as recorder:
        sim.add_observer(recorder)
        print(sim.run_until(scene.duration).brief())

    recording = jelly.read_recording(recording_path)
    print(f"{recording.frames} frames of {recording.model.num_particles} particles")
    result = jelly.fit_recording(recording, free="ks,kd", window=0.1,
                                 initial={"ks": 1400, "kd": 30},
                                 write_scene=os.path.join(args.out, "fitted.json"))
    print(result.report())
    for p in result.parameters:
        print(f"{p.name}: {p.value:.4f} +- {p.stddev:.2g} (true {truth[p.name]})")
    print(f"written: {args.out}/fitted.json")


if __name__ == "__main__":
    main()
