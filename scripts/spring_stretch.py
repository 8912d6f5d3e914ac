#!/usr/bin/env python3
"""The springs' stretch (L - l0) / l0, frame by frame, in a jelly recording: how far a material
itself stretches (docs/performance.md, "Against Bullet's soft bodies": the cloth's goal of at
most 5 % stretch against what its springs give when converged).

Usage: /usr/bin/python3 scripts/spring_stretch.py RUN.h5 [--every K]
Prints, every K-th frame (default 10) and at the last, the largest stretch and which spring
type has it, the 99th percentile, and the largest of each spring type; then the largest over
all frames.
"""
import argparse

import h5py
import numpy as np

TYPES = {0: "structural", 1: "shear", 2: "bending"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    parser.add_argument("--every", type=int, default=10, help="print every K-th frame")
    args = parser.parse_args()
    if args.every < 1:
        parser.error(f"--every = {args.every} is invalid: an integer >= 1")
    with h5py.File(args.recording, "r") as f:
        springs = f["connectivity/springs"][()]
        rest = f["connectivity/rest_length"][()]
        kind = f["connectivity/type"][()]
        # Particle positions of every body, in global particle order.
        groups = sorted(f["particles"].values(),
                        key=lambda g: int(g.attrs.get("first_particle", 0)))
        times = groups[0]["position/time"][()]
        frames = len(times)
        worst = (-np.inf, 0.0)
        for k in range(frames):
            x = np.concatenate([g["position/value"][k] for g in groups])
            stretch = (np.linalg.norm(x[springs[:, 0]] - x[springs[:, 1]], axis=1) - rest) / rest
            top = int(np.argmax(stretch))
            if stretch[top] > worst[0]:
                worst = (stretch[top], times[k])
            if k % args.every == 0 or k == frames - 1:
                per_type = ", ".join(f"{TYPES.get(int(t), t)} {stretch[kind == t].max():.4f}"
                                     for t in np.unique(kind))
                print(f"t = {times[k]:.3f} s: largest {stretch[top]:.4f} "
                      f"({TYPES.get(int(kind[top]), kind[top])}), 99th percentile "
                      f"{np.percentile(stretch, 99):.4f}; by type: {per_type}")
        print(f"largest over the run: {worst[0]:.4f} at t = {worst[1]:.3f} s")


if __name__ == "__main__":
    main()
