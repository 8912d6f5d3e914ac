#!/usr/bin/python3
"""Plots a jelly recording: centre-of-mass trajectory, energies over time and 3-D snapshots of
its bodies (shaded surfaces, or particles and springs) and terrains, in one PNG.

    scripts/plot.py out/slope.h5 [-o out/slope.png] [--snapshots 4] [--all-springs]
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import jelly_h5  # noqa: E402


def shaded(polygons, colour, light=(0.4, -0.3, 0.87)):
    """Face colours lit by a directional light (plot order x, z, y; light from above-front)."""
    n = np.cross(polygons[:, 1] - polygons[:, 0], polygons[:, 2] - polygons[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    light = np.asarray(light) / np.linalg.norm(light)
    # The plot order (x, z, y) mirrors the frame: outward normals point the other way.
    brightness = 0.35 + 0.65 * np.clip(-(n @ light), 0, 1)
    rgb = np.asarray(colour[:3])[None, :] * brightness[:, None]
    return np.hstack([rgb, np.ones((len(rgb), 1))])


def draw_snapshot(ax, rec, frame, limits, all_springs, elevation=15):
    x = rec.position[frame]
    keep = np.ones(len(rec.springs), bool) if all_springs else rec.spring_type == 0
    for X, Z, Y in jelly_h5.terrain_surfaces(rec, frame, limits):
        ax.plot_surface(X, Z, Y, color="tan", alpha=0.35, linewidth=0)
    for polygons in jelly_h5.terrain_polygons(rec, frame):
        ax.add_collection3d(Poly3DCollection(polygons, facecolor="tan", alpha=0.5, linewidth=0))
    colours = plt.get_cmap("tab10")
    drawn = np.zeros(len(x), bool)
    for k, body in enumerate(rec.bodies):
        polygons = jelly_h5.surface_polygons(body, frame)
        if polygons is None or all_springs:
            continue
        ax.add_collection3d(Poly3DCollection(polygons, facecolors=shaded(polygons, colours(k % 10)),
                                             edgecolor="k", linewidth=0.05))
        drawn[body.first_particle:body.first_particle + body.num_particles] = True
    springs = rec.springs[keep]
    springs = springs[~drawn[springs[:, 0]]]
    lines = Line3DCollection(jelly_h5.spring_segments(x, springs), colors="tab:blue",
                             linewidths=0.4, alpha=0.6)
    ax.add_collection3d(lines)
    ax.scatter(x[~drawn, 0], x[~drawn, 2], x[~drawn, 1], s=0.5, c="navy", depthshade=False)
    jelly_h5.style_axis(ax, limits)
    ax.view_init(elev=elevation, azim=-70)
    ax.set_title(f"t = {rec.time[frame]:.2f} s")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", help="a recording written by jelly (HDF5)")
    parser.add_argument("-o", "--output", help="PNG path (default: FILE with .png)")
    parser.add_argument("--snapshots", type=int, default=4, help="3-D snapshots (default 4)")
    parser.add_argument("--elevation", type=float, default=15,
                        help="the snapshots' view from above, degrees (default 15; more to see "
                             "into a bowl)")
    parser.add_argument("--all-springs", action="store_true",
                        help="draw every spring and particle instead of the surfaces "
                        "(default: surfaces; structural springs of bodies without one)")
    args = parser.parse_args()
    rec = jelly_h5.Recording(args.file)
    if rec.frames == 0:
        sys.exit(f"error: {args.file} holds no frames")
    output = args.output or os.path.splitext(args.file)[0] + ".png"

    fig = plt.figure(figsize=(16, 9), constrained_layout=True)
    grid = fig.add_gridspec(2, max(args.snapshots, 3))
    top = grid[0, :].subgridspec(1, 3)
    t = rec.time
    com = rec.observables["center_of_mass"]

    ax = fig.add_subplot(top[0, 0])
    for k, name in enumerate("xyz"):
        ax.plot(t, com[:, k], label=f"{name}")
    for terrain in rec.terrains:
        if terrain["kind"] == "elevator":
            ax.plot(t, terrain["position"][:, 1], "--", color="tan", label="platform y")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("position (m)")
    ax.set_title("Centre of mass against time")
    ax.legend()
    ax.grid(alpha=0.3)

    ax = fig.add_subplot(top[0, 1])
    ax.plot(com[:, 0], com[:, 1], color="tab:purple")
    ax.plot(com[0, 0], com[0, 1], "o", color="tab:green", label="start")
    ax.plot(com[-1, 0], com[-1, 1], "s", color="tab:red", label="end")
    for terrain in rec.terrains:
        n = np.asarray(terrain.get("normal", [0, 1, 0]), float)
        p = terrain["position"][0]
        if terrain["kind"] == "plane" and abs(n[1]) > 1e-6:
            span = com[:, 0].max() - com[:, 0].min() + 2
            xs = np.array([com[:, 0].min() - 1, com[:, 0].max() + 1]) if span > 2 else \
                np.array([com[0, 0] - 3, com[0, 0] + 3])
            ax.plot(xs, p[1] - n[0] * (xs - p[0]) / n[1], color="tan",
                    label="plane (section z = 0)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Centre-of-mass path (x-y)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend()
    ax.grid(alpha=0.3)

    ax = fig.add_subplot(top[0, 2])
    for name, label in [("kinetic_energy", "kinetic"), ("elastic_energy", "elastic"),
                        ("gravitational_energy", "gravitational"), ("total_energy", "total")]:
        if name in rec.observables:
            ax.plot(t, rec.observables[name], label=label,
                    linewidth=2 if name == "total_energy" else 1)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title("Energies")
    ax.legend()
    ax.grid(alpha=0.3)

    limits = rec.bounds()
    frames = np.unique(np.linspace(0, rec.frames - 1, args.snapshots).round().astype(int))
    for k, frame in enumerate(frames):
        draw_snapshot(fig.add_subplot(grid[1, k], projection="3d"), rec, frame, limits,
                      args.all_springs, args.elevation)
    fig.suptitle(f"{os.path.basename(args.file)}: {rec.title()}")
    fig.savefig(output, dpi=100)
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
