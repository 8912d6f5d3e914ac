#!/usr/bin/env python3
"""Triangles of a body's render surface whose centres lie inside a sphere, frame by frame, in a
jelly recording: how much of a sphere obstacle shows through a cloth draped over it
(docs/contact.md, "Thickness against terrains and obstacles").

Usage: /usr/bin/python3 scripts/surface_inside_sphere.py RUN.h5 --center 0 0.6 0 --radius 0.5
       [--body cloth]
Prints the count at the last frame, the largest count over the frames and when, and the
smallest distance of a particle's centre from the sphere's surface over the run.
"""
import argparse

import h5py
import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    parser.add_argument("--center", type=float, nargs=3, required=True, metavar=("X", "Y", "Z"))
    parser.add_argument("--radius", type=float, required=True)
    parser.add_argument("--body", default=None, help="the body's name (default: the first)")
    args = parser.parse_args()
    center = np.array(args.center)
    with h5py.File(args.recording, "r") as f:
        names = sorted(f["particles"].keys(),
                       key=lambda n: int(f["particles"][n].attrs.get("first_particle", 0)))
        name = args.body or names[0]
        group = f["particles"][name]
        triangles = group["surface/triangles"][()]
        vertices = group["surface/position/value"][()]  # [T][V][3]
        particles = group["position/value"][()]  # [T][N][3]
        time = group["position/time"][()]
    centres = vertices[:, triangles, :].mean(axis=2)  # [T][F][3]
    inside = (np.linalg.norm(centres - center, axis=2) < args.radius).sum(axis=1)
    worst = int(np.argmax(inside))
    gap = np.linalg.norm(particles - center, axis=2) - args.radius
    print("body %s: %d triangles" % (name, len(triangles)))
    print("inside the sphere at the last frame (t = %.3f s): %d" % (time[-1], inside[-1]))
    print("most inside: %d at t = %.3f s" % (inside[worst], time[worst]))
    print("closest particle centre to the sphere's surface over the run: %.4f m" % gap.min())


if __name__ == "__main__":
    main()
