#!/usr/bin/env python3
"""Contact between bodies in a jelly recording (docs/contact.md): the closest approach of
particles of different bodies over every frame, as a fraction of the sum of their contact radii,
and at the end each body's centre, the vertical gaps of a stack, the fastest particle over the
last frame and each centre's drift over the last 2 s; and whether the total energy ever grew.

Usage: /usr/bin/python3 scripts/body_gaps.py RUN.h5
(each body's contact radius is its recorded `radius` attribute)
"""
import argparse
import sys

import h5py
import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    args = parser.parse_args()
    f = h5py.File(args.recording, "r")
    names = list(f["particles"].keys())
    names.sort(key=lambda n: int(f["particles"][n].attrs["first_particle"]))
    radii = [float(f["particles"][n].attrs["radius"]) for n in names]
    positions = [f["particles/%s/position/value" % n][()] for n in names]
    time = f["observables/angular_momentum/time"][()]
    if len(names) < 2:
        sys.exit("body_gaps.py: %s has one body" % args.recording)
    closest, when = np.inf, 0.0
    for k in range(len(time)):
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                d = np.linalg.norm(positions[a][k][:, None, :] - positions[b][k][None, :, :],
                                   axis=2).min() / (radii[a] + radii[b])
                if d < closest:
                    closest, when = d, time[k]
    print("closest approach of two bodies' particles: %.2f %% of the sum of their radii at t = %.3f s"
          % (100 * closest, when))
    for a, n in enumerate(names):
        p = positions[a][-1]
        print("%-8s centre %s, y from %.3f to %.3f" % (n, np.round(p.mean(axis=0), 3),
                                                         p[:, 1].min(), p[:, 1].max()))
    for a in range(len(names) - 1):
        gap = positions[a + 1][-1][:, 1].min() - positions[a][-1][:, 1].max()
        print("vertical gap %s - %s: %.4f m" % (names[a], names[a + 1], gap))
    dt = time[-1] - time[-2]
    fastest = max(np.linalg.norm((p[-1] - p[-2]) / dt, axis=1).max() for p in positions)
    print("fastest particle over the last frame: %.4f m/s" % fastest)
    k = int(np.searchsorted(time, time[-1] - 2.0))
    for a, n in enumerate(names):
        drift = positions[a][-1].mean(axis=0) - positions[a][k].mean(axis=0)
        print("%-8s centre drift over the last %.1f s: %s m" % (n, time[-1] - time[k],
                                                                 np.round(drift, 4)))
    energy = f["observables/total_energy/value"][()]
    growth = np.diff(energy)
    print("frames where the total energy grew (> 1e-9 relative): %d (largest growth %.3g J)"
          % (int(np.sum(growth > 1e-9 * abs(energy[0]))), growth.max()))


if __name__ == "__main__":
    main()
